# SPDX-License-Identifier: MIT
"""The parameter declaration (POUR_PARAMS) against what repeats it: docs/can.md's table and the DBC's ParamId
value lists are what scripts/param_table.py generates; a declaration with two rows on one CAN id, two rows of
one name or a bound that is no number fails naming the rows involved."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts/param_table.py"
HEADER = ROOT / "firmware/include/pour/params.h"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("args", [("check",), ("docs", "--check"), ("dbc", "--check")])
def test_the_tree_agrees_with_the_declaration(args):
    r = run(*args)
    assert r.returncode == 0 and r.stderr == "", r.stderr


def test_the_envelope_ranges_are_the_safety_cases():
    sys.path.insert(0, str(SCRIPT.parent))
    try:
        import param_table
    finally:
        sys.path.pop(0)
    rows = {r["name"]: r for r in param_table.declaration()}
    for name in ("omega_max", "omega_slack", "slow_omega", "stop_return_speed", "stop_rest_omega"):
        assert rows[name]["max"] == 2_000_000, name  # docs/safety.md: 2 rad/s, the hot-liquid limit
    assert rows["alpha_max"]["max"] == 3_400_000 and rows["governor_gain"]["max"] == 16384


def _bad(tmp_path: Path, old: str, new: str) -> Path:
    text = HEADER.read_text()
    assert text.count(old) == 1, old
    bad = tmp_path / "params.h"
    bad.write_text(text.replace(old, new))
    return bad


BAD = [
    ("X(5, alpha_max,", "X(4, alpha_max,", "omega_max and alpha_max have the same CAN parameter id 4"),
    ("X(27, slow_ki,", "X(27, slow_omega,", "ids 24 and 27 have the same name slow_omega"),
    ('X(17, encoder_zero, "counts", 0, 16777215,', 'X(17, encoder_zero, "counts", 16777215, 0,',
     "encoder_zero: min 16777215 is above max 0"),
    ('X(15, node_id, "", 0, 63,', 'X(15, node_id, "", 0, NODE_MAX,',
     "node_id: bound NODE_MAX is not a number or a #define of the headers"),
]


@pytest.mark.parametrize("old,new,message", BAD, ids=["same id", "same name", "min > max", "unknown bound"])
def test_a_bad_declaration_is_refused_naming_its_rows(tmp_path, old, new, message):
    r = run("check", "--header", str(_bad(tmp_path, old, new)))
    assert r.returncode == 1 and r.stdout == "", (r.stdout, r.stderr)
    assert r.stderr.strip().splitlines() == [f"params.h: {message}"], r.stderr
    assert "Traceback" not in r.stderr


def test_a_missing_header_is_one_line(tmp_path):
    r = run("check", "--header", str(tmp_path / "none.h"))
    assert r.returncode == 1 and r.stderr.startswith("error: ") and len(r.stderr.splitlines()) == 1, r.stderr


def test_the_bridge_lists_every_field_of_the_cores_config():
    r = run("fields")
    assert r.returncode == 0 and r.stderr == "", r.stderr


def _bridge() -> Path:
    for f in sorted((ROOT / "host_sim").rglob("*.cpp")):
        if "POURSIM_FW_FIELD(safety." in f.read_text():
            return f
    raise AssertionError("no bridge source")


@pytest.mark.parametrize("old,new,message", [
    ("POURSIM_FW_FIELD(supervisor.window_ms), ", "",
     "pour_control_config_t.supervisor.window_ms has no POURSIM_FW_FIELD"),
    ("POURSIM_FW_FIELD(seed),", "POURSIM_FW_FIELD(seed), POURSIM_FW_FIELD(safety.omega_max),",
     "POURSIM_FW_FIELD(safety.omega_max) is no field of pour_control_config_t"),
], ids=["a field left out", "a path that is no field"])
def test_a_bridge_that_drifts_is_named(tmp_path, old, new, message):
    text = _bridge().read_text()
    assert text.count(old) == 1, old
    bad = tmp_path / "core_api.cpp"
    bad.write_text(text.replace(old, new))
    r = run("fields", "--bridge", str(bad))
    assert r.returncode == 1 and r.stderr.strip().splitlines() == [f"{bad}: {message}"], r.stderr


@pytest.mark.parametrize("old,new,message", [
    ("X(5, alpha_max,", "X(4, alpha_max,", "duplicate case value"),
    ("X(27, slow_ki,", "X(27, slow_omega,", "POUR_PARAM_ID_slow_omega"),
    ('X(17, encoder_zero, "counts", 0, 16777215,', 'X(17, encoder_zero, "counts", 16777215, 0,',
     "pour_param_range_not_empty_encoder_zero"),
], ids=["same id", "same name", "min > max"])
def test_the_compiler_refuses_a_bad_declaration_too(tmp_path, old, new, message):
    include = tmp_path / "include"
    shutil.copytree(HEADER.parent.parent, include)
    (include / "pour/params.h").write_text(HEADER.read_text().replace(old, new))
    def compile_with(inc: Path) -> subprocess.CompletedProcess:
        return subprocess.run([shutil.which("cc") or "cc", "-std=c99", "-fsyntax-only", "-I", str(inc),
                               str(ROOT / "firmware/src/params.c")], capture_output=True, text=True, timeout=60)
    good = compile_with(HEADER.parent.parent)
    assert good.returncode == 0, good.stderr  # the same command takes the real declaration
    r = compile_with(include)
    assert r.returncode != 0 and message in r.stderr, r.stderr
