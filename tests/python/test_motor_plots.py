# SPDX-License-Identifier: MIT
"""pour.eval.motor_plots: PNGs from bench_motor's traces, and a clear error for a bad trace."""
from __future__ import annotations

from pathlib import Path

from pour.eval import motor_plots


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def test_writes_both_pngs(tmp_path: Path) -> None:
    step = _write(tmp_path / "s.csv", "t_s,iq_a\n" + "".join(f"{k * 5e-5},{min(10.0, k * 0.5)}\n" for k in range(200)))
    bus = _write(tmp_path / "b.csv", "t_s,vbus_v\n" + "".join(f"{k * 1e-3},{24 + 0.001 * k}\n" for k in range(300)))
    assert motor_plots.main(["--step", str(step), "--bus", str(bus), "--out", str(tmp_path / "img")]) == 0
    for name in ("motor_current_step.png", "motor_bus_pour.png"):
        png = tmp_path / "img" / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_traces_exit_2_naming_the_file(tmp_path: Path, capsys) -> None:
    good = _write(tmp_path / "b.csv", "t_s,vbus_v\n0,24\n")
    cases = {
        "missing.csv": None,
        "wrong_columns.csv": "time,current\n0,1\n",
        "empty.csv": "t_s,iq_a\n",
        "not_a_number.csv": "t_s,iq_a\n0,abc\n",
        "not_finite.csv": "t_s,iq_a\n0,nan\n",
    }
    for name, text in cases.items():
        path = tmp_path / name
        if text is not None:
            _write(path, text)
        assert motor_plots.main(["--step", str(path), "--bus", str(good), "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err
        assert "motor_plots: error:" in err and name in err, err
    assert not (tmp_path / "o" / "motor_current_step.png").exists()
