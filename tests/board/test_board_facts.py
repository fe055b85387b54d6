# SPDX-License-Identifier: MIT
"""The board-facts table (pour/board_facts.h) against its copy in docs/board.md, and the refusals: a row
without a source (refused by the generator and by the compiler), a changed value, bad input."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import board_facts  # noqa: E402

SOURCE = Path(os.environ.get("POUR_SOURCE_DIR", HERE.parents[1]))
HEADER = SOURCE / "firmware" / "motor" / "include" / "pour" / "board_facts.h"
DOC = SOURCE / "docs" / "board.md"


def run(capsys, *args: str) -> tuple[int, str]:
    status = board_facts.main(list(args))
    c = capsys.readouterr()
    return status, c.out + c.err


def test_docs_hold_the_headers_tables(capsys):
    status, out = run(capsys, "--header", str(HEADER), "--check", str(DOC))
    assert status == 0, out
    facts, pins = board_facts.load(HEADER)
    names = {f.name: f.value for f in facts}
    # the findings of issue 35, as the table now states them
    assert names["PGA_GAIN"] == 16 and names["CURRENT_SIGN"] == -1 and names["VBUS_DIVIDER_MILLI"] == 10389
    assert names["OFFSET_NOMINAL_COUNTS"] == 2553 and names["IDLE_LOW_SIDE_ON"] == 0
    assert abs(names["BIAS_MV"] * 4096 / names["ADC_VREF_MV"] - names["OFFSET_NOMINAL_COUNTS"]) < 1
    ratio = (names["VBUS_R_TOP_OHM"] + names["VBUS_R_BOTTOM_OHM"]) / names["VBUS_R_BOTTOM_OHM"]
    assert abs(ratio * 1000 - names["VBUS_DIVIDER_MILLI"]) < 1
    used = {p.name: f"P{p.port}{p.pin}" for p in pins}
    assert used["BRAKE"] != "PB12" and used["POWER"] != "PB8"  # the potentiometer, BOOT0
    assert used["POT"] == "PB12"


def test_a_changed_value_fails_the_check(tmp_path, capsys):
    header = tmp_path / "board_facts.h"
    header.write_text(HEADER.read_text().replace("X(VBUS_DIVIDER_MILLI, 10389,", "X(VBUS_DIVIDER_MILLI, 19170,"))
    status, out = run(capsys, "--header", str(header), "--check", str(DOC))
    assert status == 1 and "differ" in out


def test_a_row_without_a_source_is_refused(tmp_path, capsys):
    text = HEADER.read_text()
    old = '"[stim] utils.cpp ntc_voltage_to_temp Beta 3425"'
    assert old in text
    (tmp_path / "bad").mkdir()
    header = tmp_path / "bad" / "board_facts.h"
    header.write_text(text.replace(old, '""'))
    status, out = run(capsys, "--header", str(header), "--check", str(DOC))
    assert status == 2 and "NTC_BETA_K: no source" in out
    # and the compiler refuses it too: the header's per-row check
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "no C compiler"
    src = tmp_path / "t.c"
    src.write_text('#include "board_facts.h"\nint main(void) { return POUR_BOARD_NTC_BETA_K == 3425 ? 0 : 1; }\n')
    bad = subprocess.run([cc, "-fsyntax-only", "-I", str(header.parent), str(src)], capture_output=True, text=True)
    assert bad.returncode != 0 and "NTC_BETA_K_has_a_source" in bad.stderr
    good = subprocess.run([cc, "-fsyntax-only", "-I", str(HEADER.parent), str(src)], capture_output=True, text=True)
    assert good.returncode == 0, good.stderr


def test_bad_input_is_refused_with_a_reason(tmp_path, capsys):
    status, out = run(capsys, "--header", str(tmp_path / "nowhere.h"), "--check", str(DOC))
    assert status == 2 and "cannot read" in out
    doc = tmp_path / "board.md"
    doc.write_text("# no markers\n")
    status, out = run(capsys, "--header", str(HEADER), "--check", str(doc))
    assert status == 2 and "markers are missing" in out
    header = tmp_path / "h.h"
    header.write_text("#define POUR_BOARD_FACTS(X) X(A, zero, \"u\", \"w\", \"a source\")\n#define POUR_BOARD_PINS(X)\n")
    status, out = run(capsys, "--header", str(header), "--check", str(DOC))
    assert status == 2 and "not an integer" in out


def test_write_renames_a_complete_file(tmp_path, capsys):
    doc = tmp_path / "board.md"
    doc.write_text(f"head\n{board_facts.BEGIN}\nold\n{board_facts.END}\ntail\n")
    status, _ = run(capsys, "--header", str(HEADER), "--write", str(doc))
    assert status == 0
    text = doc.read_text()
    assert text.startswith("head\n") and text.endswith("tail\n") and "`SHUNT_UOHM` | 3000" in text
    assert [p.name for p in tmp_path.iterdir()] == ["board.md"]
