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
    board_c = (SOURCE / "firmware" / "ports" / "cortex-m4" / "board" / "board_stm32g431.c").read_text()
    used = set(re.findall(r"(?:BOARD_PIN|AF_PIN)\((\w+)\)", board_c)) - {"name"}
    assert used and used <= pins, used - pins


def test_every_written_field_has_a_meaning_checked(table):
    writes = [line for line in table.read_text().splitlines() if line.startswith("WRITE ")]
    assert len(writes) >= 80
    blocks = {w.split()[1] for w in writes}
    for needed in ("OPAMP", "TIM1", "TIM4", "COMP", "DAC", "ADC1", "ADC2", "ADC12", "RCC", "PWR", "FLASH", "IWDG",
                   "LPTIM", "FDCAN", "GPIOA", "GPIOB", "GPIOC"):
        assert needed in blocks, needed  # every peripheral the port's drivers write is decoded
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


def _mutated(table: Path, tmp_path: Path, swaps: dict[str, str]) -> Path:
    text = table.read_text()
    for good, bad in swaps.items():
        assert good + "\n" in text, good
        text = text.replace(good + "\n", bad + "\n")
    out = tmp_path / "table.txt"
    out.write_text(text)
    return out


def test_a_wrong_adc_sample_time_or_trigger_fails(crate, table, tmp_path, capsys):
    """U sampled for 2.5 cycles instead of ST's 6.5, the bus for 6.5 instead of 47.5, a falling-edge trigger."""
    bad = _mutated(table, tmp_path, {"WRITE ADC1 SMPR1 SMP3 1": "WRITE ADC1 SMPR1 SMP3 0",
                                     "WRITE ADC1 SMPR1 SMP1 4": "WRITE ADC1 SMPR1 SMP1 1",
                                     "WRITE ADC2 JSQR JEXTEN 1": "WRITE ADC2 JSQR JEXTEN 2",
                                     "WRITE ADC1 JSQR JSQ2 12": "WRITE ADC1 JSQR JSQ2 18"})
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "WRITE ADC1.SMPR1.SMP3 = 0 means '2.5 ADC clock cycles', the intent is '6.5 ADC clock cycles'" in out
    assert "WRITE ADC1.SMPR1.SMP1 = 1 means '6.5 ADC clock cycles', the intent is '47.5 ADC clock cycles'" in out
    assert "WRITE ADC2.JSQR.JEXTEN = 2 means 'Trigger detection on the falling edge'" in out
    assert "WRITE ADC1.JSQR.JSQ2 = 18: the intent is 12" in out


def test_a_wrong_clock_fails(crate, table, tmp_path, capsys):
    """The PLL from HSI16 instead of the crystal, three flash wait states at 170 MHz, range 1 normal."""
    bad = _mutated(table, tmp_path, {"WRITE RCC PLLCFGR PLLSRC 3": "WRITE RCC PLLCFGR PLLSRC 2",
                                     "WRITE FLASH ACR LATENCY 4": "WRITE FLASH ACR LATENCY 3",
                                     "WRITE PWR CR5 R1MODE 0": "WRITE PWR CR5 R1MODE 1"})
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "WRITE RCC.PLLCFGR.PLLSRC = 2 means 'HSI16 sent to PLL input', the intent is 'HSE sent to PLL input'" in out
    assert "WRITE FLASH.ACR.LATENCY = 3 means 'Three Wait States (Vcore Boost 1 (<= 136MHz)" in out
    assert "WRITE PWR.CR5.R1MODE = 1: the intent is 0" in out


def test_a_pin_in_the_wrong_mode_fails(crate, table, tmp_path, capsys):
    """A gate pin left an output instead of TIM1's alternate function, a shunt input digital, the power enable
    driven high at start-up, an encoder pin on AF1, a gate pin at low speed (the port's old value)."""
    bad = _mutated(table, tmp_path, {"WRITE GPIOA MODER MODER8 2": "WRITE GPIOA MODER MODER8 1",
                                     "WRITE GPIOA MODER MODER1 3": "WRITE GPIOA MODER MODER1 0",
                                     "WRITE GPIOA ODR ODR15 0": "WRITE GPIOA ODR ODR15 1",
                                     "WRITE GPIOB AFRL AFRL6 2": "WRITE GPIOB AFRL AFRL6 1",
                                     "WRITE GPIOC OSPEEDR OSPEEDR13 2": "WRITE GPIOC OSPEEDR OSPEEDR13 0"})
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "WRITE GPIOA.MODER.MODER8 = 1 means 'General purpose output mode', the intent is 'Alternate function mode'" in out
    assert "WRITE GPIOA.MODER.MODER1 = 0 means 'Input mode (reset state)', the intent is 'Analog mode'" in out
    assert "WRITE GPIOA.ODR.ODR15 = 1 means 'Set output to logic high'" in out
    assert "WRITE GPIOB.AFRL.AFRL6 = 1 means 'AF1', the intent is 'AF2'" in out
    assert "WRITE GPIOC.OSPEEDR.OSPEEDR13 = 0 means 'Low speed', the intent is 'High speed'" in out


def test_a_wrong_watchdog_prescaler_fails(crate, table, tmp_path, capsys):
    """LSI / 8 doubles the 10 ms timeout; a reload one count short."""
    bad = _mutated(table, tmp_path, {"WRITE IWDG PR PR 0": "WRITE IWDG PR PR 1",
                                     "WRITE IWDG RLR RL 84": "WRITE IWDG RLR RL 83"})
    status, out = run(crate, bad, capsys)
    assert status == 1
    assert "WRITE IWDG.PR.PR = 1 means 'Divider /8', the intent is 'Divider /4'" in out
    assert "WRITE IWDG.RLR.RL = 83: the intent is 84" in out


def test_a_wrong_fdcan_mode_fails(crate, table, tmp_path, capsys):
    """FD frames on, bus monitoring, a prescaler that gives 1.13 Mbit/s, non-matching frames accepted."""
    bad = _mutated(table, tmp_path, {"WRITE FDCAN CCCR FDOE 0": "WRITE FDCAN CCCR FDOE 1",
                                     "WRITE FDCAN CCCR MON 0": "WRITE FDCAN CCCR MON 1",
                                     "WRITE FDCAN NBTP NBRP 9": "WRITE FDCAN NBTP NBRP 8",
                                     "WRITE FDCAN RXGFC ANFS 2": "WRITE FDCAN RXGFC ANFS 0"})
    status, out = run(crate, bad, capsys)
    assert status == 1
    for field, want in (("CCCR.FDOE = 1", 0), ("CCCR.MON = 1", 0), ("NBTP.NBRP = 8", 9), ("RXGFC.ANFS = 0", 2)):
        assert f"WRITE FDCAN.{field}: the intent is {want}" in out


def test_every_pin_the_board_sets_up_is_decoded(table):
    """The pins with GPIO WRITE lines are the pins board_stm32g431.c sets up, no more (the rest stay at reset)."""
    text = table.read_text()
    pins = {line.split()[2]: line.split()[1] for line in text.splitlines() if line.startswith("PIN ")}
    moder = [w.split() for w in text.splitlines() if w.startswith("WRITE GPIO") and w.split()[2] == "MODER"]
    written = {"P" + w[1][4] + w[3][len("MODER"):] for w in moder}
    board_c = (SOURCE / "firmware" / "ports" / "cortex-m4" / "board" / "board_stm32g431.c").read_text()
    used = set(re.findall(r"(?:BOARD_PIN|AF_PIN)\((\w+)\)", board_c)) - {"name"}
    assert {pins[p] for p in written} == used
