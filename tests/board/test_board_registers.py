# SPDX-License-Identifier: MIT
"""The port's register tables against ST's description of the STM32G431 (the stm32g4 crate, fetched by
scripts/setup.sh into cargo's home) and every pin of the board's table (pour/board_facts.h) against ST's pin
database (the stm32-metapac crate), and the check's own refusal paths: a deliberately wrong offset, a wrong
alternate function and a pin the package lacks in our table, a deliberately wrong field position in a copy
of ST's sources, and bad input."""
from __future__ import annotations

import os
import re
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
def metapac() -> Path:
    marker = SOURCE / ".deps" / "stm32g4" / "metapac-dir"
    assert marker.is_file(), f"{marker} missing: run scripts/setup.sh (it fetches the stm32-metapac crate)"
    path = Path(marker.read_text().strip())
    assert (path / "src" / "chips" / "stm32g431cb" / "metadata.rs").is_file(), f"{path}: not the stm32-metapac crate"
    return path


@pytest.fixture(scope="module")
def table(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("regs") / "table.txt"
    text = subprocess.run([str(BUILD / "bin" / "board_regtable")], check=True, capture_output=True,
                          text=True).stdout
    out.write_text(text)
    return out


METAPAC: Path | None = None


@pytest.fixture(autouse=True)
def _with_metapac(metapac):
    global METAPAC
    METAPAC = metapac


INTENTS = HERE / "register_intents.txt"


def run(crate: Path, table: Path, capsys, metapac: Path | None = None, intents: Path = INTENTS) -> tuple[int, str]:
    status = check_registers.main(["--crate", str(crate), "--table", str(table), "--metapac", str(metapac or METAPAC),
                                   "--intents", str(intents)])
    captured = capsys.readouterr()
    return status, captured.out + captured.err


def test_port_tables_match_st(crate, table, capsys):
    status, out = run(crate, table, capsys)
    assert status == 0, out
    lines = table.read_text().splitlines()
    for needed in ("PERIPH RCC", "PERIPH FDCAN1", "REG FDCAN NBTP", "FIELD RCC PLLCFGR PLLN", "PIN PWM_UL PC13 TIM1 CH1N 4",
                   "PIN CAN_TX PB9 FDCAN1 TX 9", "PIN AMP_W PB1 OPAMP3 VOUT -1", "PIN BRAKE PB3 GPIO OUT -1"):
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


def test_every_pin_the_port_uses_is_checked(table):
    """Each pin of pour/board_facts.h's table, and each pin the board's code names, is a PIN line."""
    pins = {line.split()[1] for line in table.read_text().splitlines() if line.startswith("PIN ")}
    board_c = (SOURCE / "firmware" / "ports" / "cortex-m4" / "board_stm32g431.c").read_text()
    used = set(re.findall(r"(?:BOARD_PIN|AF_PIN)\((\w+)\)", board_c)) - {"name"}
    assert used and used <= pins, used - pins


def test_every_written_field_has_a_meaning_checked(table):
    writes = [line for line in table.read_text().splitlines() if line.startswith("WRITE ")]
    assert len(writes) >= 80
    intents = check_registers.load_intents(INTENTS)
    for w in writes:
        assert tuple(w.split()[1:4]) in intents, w


def test_a_wrong_mode_fails_by_its_meaning(crate, table, tmp_path, capsys):
    """The op-amps as the port had them (VM_SEL VINM0: open loop), a PGA gain without the VINM0 bias, the
    low sides on at a break: each decoded through ST's enumerated values and refused against the intent."""
    text = table.read_text()
    for good in ("WRITE OPAMP OPAMP1_CSR VM_SEL 2\n", "WRITE OPAMP OPAMP2_CSR PGA_GAIN 11\n", "WRITE TIM1 CR2 OIS2N 0\n"):
        assert good in text, good
    bad = tmp_path / "table.txt"
    bad.write_text(text.replace("WRITE OPAMP OPAMP1_CSR VM_SEL 2\n", "WRITE OPAMP OPAMP1_CSR VM_SEL 0\n")
                   .replace("WRITE OPAMP OPAMP2_CSR PGA_GAIN 11\n", "WRITE OPAMP OPAMP2_CSR PGA_GAIN 3\n")
                   .replace("WRITE TIM1 CR2 OIS2N 0\n", "WRITE TIM1 CR2 OIS2N 1\n")
                   .replace("WRITE TIM1 ARR ARR 4250\n", "WRITE TIM1 ARR ARR 4251\n")
                   .replace("WRITE OPAMP OPAMP3_CSR PGA_GAIN 11\n", "WRITE OPAMP OPAMP3_CSR PGA_GAIN 7\n")
                   + "WRITE TIM1 CR1 URS 1\n")
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert ("WRITE OPAMP.OPAMP1_CSR.VM_SEL = 0 means 'VINM0 connected to VINM input', the intent is "
            "'Feedback resistor connected to VINM (PGA mode)'") in out
    assert "WRITE OPAMP.OPAMP2_CSR.PGA_GAIN = 3 means 'Gain 16', the intent is 'Gain 16, input/bias connected" in out
    assert "WRITE TIM1.CR2.OIS2N = 1 means 'OCxN=1 after a dead-time when MOE=0'" in out
    assert "WRITE TIM1.ARR.ARR = 4251: the intent is 4250" in out
    assert "WRITE OPAMP.OPAMP3_CSR.PGA_GAIN = 7: no meaning in ST's description" in out
    assert "WRITE TIM1.CR1.URS = 1: no declared intent" in out


def test_bad_intents_are_refused_with_a_reason(crate, table, tmp_path, capsys):
    bad = tmp_path / "intents.txt"
    bad.write_text("OPAMP OPAMP1_CSR VM_SEL | PGA\n")
    status, out = run(crate, table, capsys, intents=bad)
    assert status == 2 and "intents.txt line 1" in out
    bad.write_text("# nothing\n")
    status, out = run(crate, table, capsys, intents=bad)
    assert status == 2 and "no intent" in out
    status, out = run(crate, table, capsys, intents=tmp_path / "nowhere.txt")
    assert status == 2 and "cannot read" in out


def test_wrong_alternate_function_in_our_table_fails(crate, table, tmp_path, capsys):
    text = table.read_text()
    bad = tmp_path / "table.txt"
    bad.write_text(text.replace("PIN PWM_UL PC13 TIM1 CH1N 4", "PIN PWM_UL PC13 TIM1 CH1N 6")
                   .replace("PIN CAN_TX PB9 FDCAN1 TX 9", "PIN CAN_TX PB8 FDCAN1 TX 9")
                   .replace("PIN AMP_W PB1 OPAMP3 VOUT -1", "PIN AMP_W PB1 OPAMP3 VOUT 7")
                   .replace("PIN LED PC6 GPIO OUT -1", "PIN LED PC16 GPIO OUT -1"))
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "PIN PWM_UL: TIM1.CH1N on PC13 with AF6, ST's AF4" in out
    assert "PIN CAN_TX: FDCAN1 has no TX on PB8 in ST's pin database" in out
    assert "PIN AMP_W: OPAMP3.VOUT on PB1 with AF7, ST's none" in out
    assert "PIN LED: PC16 is not a pin of the STM32G431CB's package" in out
    status, out = run(crate, table, capsys, metapac=tmp_path / "nowhere")
    assert status == 2 and "cannot read" in out and "metadata.rs" in out


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
