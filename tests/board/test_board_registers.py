# SPDX-License-Identifier: MIT
"""The port's register tables against ST's description of the STM32G431 (the stm32g4 crate, fetched by
scripts/setup.sh into cargo's home) and the board's alternate-function pins against the stm32g4xx-hal
crate's pin maps, and the check's own refusal paths: a deliberately wrong offset and a wrong alternate
function in our table, a deliberately wrong field position in a copy of ST's sources, and bad input."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import check_registers  # noqa: E402

SOURCE = Path(os.environ.get("POUR_SOURCE_DIR", HERE.parents[1]))
BUILD = Path(os.environ.get("POUR_BUILD_DIR", SOURCE / "build" / "host"))


@pytest.fixture(scope="module")
def crate() -> Path:
    marker = SOURCE / ".deps" / "stm32g4" / "crate-dir"
    assert marker.is_file(), f"{marker} missing: run scripts/setup.sh (it fetches the stm32g4 crate)"
    path = Path(marker.read_text().strip())
    assert (path / "src" / "stm32g431" / "mod.rs").is_file(), f"{path}: not the stm32g4 crate"
    return path


@pytest.fixture(scope="module")
def hal() -> Path:
    marker = SOURCE / ".deps" / "stm32g4" / "hal-dir"
    assert marker.is_file(), f"{marker} missing: run scripts/setup.sh (it fetches the stm32g4xx-hal crate)"
    path = Path(marker.read_text().strip())
    assert (path / "src" / "pwm.rs").is_file(), f"{path}: not the stm32g4xx-hal crate"
    return path


@pytest.fixture(scope="module")
def table(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("regs") / "table.txt"
    text = subprocess.run([str(BUILD / "bin" / "board_regtable")], check=True, capture_output=True,
                          text=True).stdout
    out.write_text(text)
    return out


HAL: Path | None = None


@pytest.fixture(autouse=True)
def _with_hal(hal):
    global HAL
    HAL = hal


def run(crate: Path, table: Path, capsys, hal: Path | None = None) -> tuple[int, str]:
    status = check_registers.main(["--crate", str(crate), "--table", str(table), "--hal", str(hal or HAL)])
    captured = capsys.readouterr()
    return status, captured.out + captured.err


def test_port_tables_match_st(crate, table, capsys):
    status, out = run(crate, table, capsys)
    assert status == 0, out
    lines = table.read_text().splitlines()
    for needed in ("PERIPH RCC", "PERIPH FDCAN1", "REG FDCAN NBTP", "FIELD RCC PLLCFGR PLLN", "AF TIM1 CH1N PC13 4",
                   "AF FDCAN1 TX PB9 9"):
        assert any(line.startswith(needed) for line in lines), needed
    checked = int(out.split("check_registers: ")[1].split()[0])
    assert checked >= len(lines), out  # every line is checked once per instance of its block


def test_wrong_offset_in_our_table_fails(crate, table, tmp_path, capsys):
    text = table.read_text()
    assert "REG FDCAN NBTP 0x01c\n" in text
    bad = tmp_path / "table.txt"
    bad.write_text(text.replace("REG FDCAN NBTP 0x01c\n", "REG FDCAN NBTP 0x020\n"))
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "MISMATCH FDCAN.NBTP: offset 0x20, ST's 0x1c" in out


def test_wrong_alternate_function_in_our_table_fails(crate, table, tmp_path, capsys):
    text = table.read_text()
    bad = tmp_path / "table.txt"
    bad.write_text(text.replace("AF TIM1 CH1N PC13 4", "AF TIM1 CH1N PC13 6")
                   .replace("AF FDCAN1 TX PB9 9", "AF FDCAN1 TX PB8 9"))
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "AF TIM1.CH1N on PC13: AF6, the HAL's AF4" in out
    assert "AF FDCAN1.TX on PB8: the HAL has no such pin for it" in out
    status, out = run(crate, table, capsys, hal=tmp_path / "nowhere")
    assert status == 2 and "cannot read" in out and "pwm.rs" in out


def test_wrong_base_and_field_in_our_table_fail(crate, table, tmp_path, capsys):
    text = table.read_text()
    bad = tmp_path / "table.txt"
    bad.write_text(text.replace("PERIPH GPIOB GPIO 0x48000400", "PERIPH GPIOB GPIO 0x48000800")
                   .replace("FIELD RCC PLLCFGR PLLN 8 7", "FIELD RCC PLLCFGR PLLN 8 6")
                   .replace("FIELD FDCAN CCCR INIT 0 1", "FIELD FDCAN CCCR INIT_X 0 1"))
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "GPIOB: base 0x48000800, ST's 0x48000400" in out
    assert "RCC.PLLCFGR.PLLN: bits 8+6, ST's 8+7" in out
    assert "FDCAN.CCCR.INIT_X: no field init_x" in out


def test_wrong_offset_in_a_copy_of_st_fails(crate, table, tmp_path, capsys):
    """A copy of ST's sources with one register moved: the check reads the crate, not a list of its own."""
    src = crate / "src" / "stm32g431"
    copy = tmp_path / "crate" / "src" / "stm32g431"
    copy.mkdir(parents=True)
    for entry in src.iterdir():
        if entry.name != "fdcan.rs":
            (copy / entry.name).symlink_to(entry)
    text = (src / "fdcan.rs").read_text()
    assert "///0x1c - FDCAN nominal bit timing" in text
    (copy / "fdcan.rs").write_text(text.replace("///0x1c - FDCAN nominal bit timing", "///0x20 - FDCAN nominal bit timing"))
    status, out = run(tmp_path / "crate", table, capsys)
    assert status == 1
    assert "MISMATCH FDCAN.NBTP: offset 0x1c, ST's 0x20" in out


def test_bad_input_is_refused_with_a_reason(crate, table, tmp_path, capsys):
    status, out = run(tmp_path / "nowhere", table, capsys)
    assert status == 2 and "cannot read" in out and "mod.rs" in out
    bad = tmp_path / "table.txt"
    bad.write_text("PERIPH RCC RCC 0x40021000\nREG RCC CR zero\n")
    status, out = run(crate, bad, capsys)
    assert status == 2 and "table line 2" in out
    bad.write_text("")
    status, out = run(crate, bad, capsys)
    assert status == 2 and "no PERIPH line" in out
    bad.write_text("PERIPH NOPE NOPE 0x1\n")
    status, out = run(crate, bad, capsys)
    assert status == 1 and "NOPE: no such peripheral" in out
