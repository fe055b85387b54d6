# SPDX-License-Identifier: MIT
"""pour_virtual_board --profile: instruction counts per exception handler and per 1 kHz step, nesting aware.

A hand-written image whose every count is known from its source checks the arithmetic (a step preempted by
SysTick, which an interrupt of higher priority preempts in turn); the flashed image then has its handlers
named from its symbols and its control step held to the bar (docs/virtual-board.md, "Cycle counts").
POUR_VB and POUR_ELF come from tests/virtual_board/CMakeLists.txt.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

VB = os.environ["POUR_VB"]
ELF = os.environ["POUR_ELF"]
CC = shutil.which("arm-none-eabi-gcc")

EXC = re.compile(r"^profile: exception (\d+) \((?:IRQ|system) -?\d+\) (\S+): (\d+) entries, instructions mean ([\d.]+) "
                 r"worst (\d+) \(with what nested in it: worst (\d+)\); cycles mean (\d+) worst (\d+) = ([\d.]+) % / "
                 r"([\d.]+) % of the 50 us period; (\d+) entries nested", re.M)
FUNC = re.compile(r"^profile: function (\S+): (\d+) calls, instructions excluding interrupts mean ([\d.]+) worst (\d+), "
                  r"including them mean ([\d.]+) worst (\d+); (\d+) calls preempted", re.M)


def profile(*args: str) -> tuple[dict, dict, str]:
    r = subprocess.run([VB, "--profile", *args], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    excs = {m[2]: {"exc": int(m[1]), "entries": int(m[3]), "mean": float(m[4]), "worst": int(m[5]),
                   "worst_nested": int(m[6]), "cycles_worst": int(m[8]), "share_worst": float(m[10]),
                   "nested": int(m[11])} for m in EXC.finditer(r.stdout)}
    funcs = {m[1].split(".")[0]: {"calls": int(m[2]), "mean": float(m[3]), "worst": int(m[4]),
                                  "incl_mean": float(m[5]), "incl_worst": int(m[6]), "preempted": int(m[7])}
             for m in FUNC.finditer(r.stdout)}
    funcs.update({m[1]: {"calls": 0} for m in re.finditer(r"^profile: function (\S+): 0 calls$", r.stdout, re.M)})
    return excs, funcs, r.stdout


# Thread mode calls pour_control_step for ever: 1 + 2 x 3000 + 1 = 6002 instructions (entry block ldr, subs, bne;
# 2999 more loop blocks; bx). SysTick every 10,000 cycles at priority 0x80: 6 + 2 x 99 + 1 = 205 of its own,
# and it pends IRQ 0 (priority 0), which preempts it at once: 3 + 2 x 49 + 1 = 102.
NESTING = """
.syntax unified
.thumb
.section .text
.word 0x20008000
.word start + 1
.rept 13
.word 0
.endr
.word systick + 1
.word irq0 + 1
.thumb_func
start:
  ldr r0, =0xE000ED20
  ldr r1, =0x80000000
  str r1, [r0]
  ldr r0, =0xE000E100
  movs r1, #1
  str r1, [r0]
  ldr r0, =0xE000E010
  ldr r1, =9999
  str r1, [r0, #4]
  movs r1, #0
  str r1, [r0, #8]
  movs r1, #7
  str r1, [r0]
loop:
  bl pour_control_step
  b loop
.thumb_func
.type pour_control_step, %function
pour_control_step:
  ldr r2, =3000
1:
  subs r2, #1
  bne 1b
  bx lr
.thumb_func
.type systick, %function
systick:
  ldr r0, =0xE000E200
  movs r1, #1
  str r1, [r0]
  movs r3, #100
2:
  subs r3, #1
  bne 2b
  bx lr
.thumb_func
.type irq0, %function
irq0:
  movs r3, #50
3:
  subs r3, #1
  bne 3b
  bx lr
.ltorg
"""


def test_profile_counts_each_handler_and_the_step_with_and_without_what_preempts_it(tmp_path: Path):
    assert CC, "arm-none-eabi-gcc is needed (scripts/setup.sh's toolchain)"
    src, elf = tmp_path / "nesting.S", tmp_path / "nesting.elf"
    src.write_text(NESTING)
    subprocess.run([CC, "-mcpu=cortex-m4", "-mthumb", "-nostdlib", "-Wl,-Ttext=0x08000000", "-Wl,-e,start",
                    "-o", str(elf), str(src)], check=True, capture_output=True)
    excs, funcs, out = profile("--elf", str(elf), "--seconds", "0.05")  # 800,000 cycles at HSI16
    tick, irq = excs["systick"], excs["irq0"]
    assert (tick["exc"], irq["exc"]) == (15, 16), out
    assert tick["entries"] == 79, out  # SysTick's underflows at 13 + 10,000 k cycles (13: the set-up) within 800,000
    assert irq["entries"] == tick["entries"] and irq["nested"] == irq["entries"] and tick["nested"] == 0, out
    assert (tick["mean"], tick["worst"]) == (205.0, 205), out
    assert tick["worst_nested"] == 205 + 102, out
    assert (irq["mean"], irq["worst"], irq["worst_nested"]) == (102.0, 102, 102), out
    # Cycles: the instructions at CPI 1 plus 12 for the entry and 10 for the return.
    assert tick["cycles_worst"] == 205 + 22 and irq["cycles_worst"] == 102 + 22, out
    step = funcs["pour_control_step"]
    assert step["calls"] > 100 and step["mean"] == 6002.0 and step["worst"] == 6002, out
    # The worst call had SysTick (with IRQ 0 in it) inside: their instructions, not their entry cycles.
    assert step["incl_worst"] == 6002 + 205 + 102, out
    assert 0 < step["preempted"] < step["calls"], out


def test_profile_of_the_flashed_image_pouring_holds_the_decision_tick_to_the_bar():
    # The closed loop (--pour: calibrated, the rig's states over the bus, the shipped policy in RUN): every
    # decision on the exact image, its step <= 1,000 instructions of its own; no softmax anywhere (a greedy
    # policy), which would add ~485 to the decision tick and fail the bar.
    excs, funcs, out = profile("--elf", ELF, "--pour", "--seed", "1")
    decide, step = funcs["pour_policy_decide"], funcs["pour_control_step"]
    assert decide["calls"] >= 1000, out  # 10 s of RUN, a decision every 10 ms
    assert 0 < step["worst"] <= 1000, out
    assert decide["worst"] < step["worst"], out
    for name in ("pour_policy_softmax_q15", "pour_policy_fill_probs"):
        assert funcs.get(name, {"calls": 0})["calls"] == 0, out
    isr = excs["pour_board_drive_isr"]
    assert isr["entries"] > 190000 and isr["share_worst"] < 100.0, out  # 20 kHz over the pour, within its period


def test_profile_of_the_flashed_image_names_its_handlers_and_holds_the_step_to_the_bar():
    excs, funcs, out = profile("--elf", ELF, "--seconds", "1")
    isr, tick = excs["pour_board_drive_isr"], excs["pour_hal_timer_isr"]
    assert isr["exc"] == 16 + 18, out  # ADC1_2 (RM0440 table 97): the current loop's end of conversion
    assert tick["exc"] == 15 and 980 <= tick["entries"] <= 1000, out  # 1 kHz from the start-up's end (~11 ms) on
    # The current loop at the configured 20 kHz from the drive's start (~11 ms) on, also while the uncalibrated
    # drive holds its phases shorted: a TIM1 update event (EGR.UG) on every call restarted the period (32 kHz).
    assert 19600 <= isr["entries"] <= 20000, out
    assert isr["worst"] <= 850, out  # the motor section's bar (scripts/bench.sh motor)
    step, loop = funcs["pour_control_step"], funcs["pour_board_loop_tick"]
    assert abs(step["calls"] - tick["entries"]) <= 1 and step["calls"] == loop["calls"], out
    assert 0 < step["worst"] <= 1000, out
    assert loop["worst"] >= step["worst"], out
    # A greedy image computes no softmax in any tick.
    for name in ("pour_policy_softmax_q15", "pour_policy_fill_probs"):
        assert funcs.get(name, {"calls": 0})["calls"] == 0, out


def test_profile_of_an_image_without_symbols_is_refused_in_one_line(tmp_path: Path):
    assert CC, "arm-none-eabi-gcc is needed (scripts/setup.sh's toolchain)"
    src, elf = tmp_path / "nesting.S", tmp_path / "stripped.elf"
    src.write_text(NESTING)
    subprocess.run([CC, "-mcpu=cortex-m4", "-mthumb", "-nostdlib", "-Wl,-Ttext=0x08000000", "-Wl,-e,start", "-s",
                    "-o", str(elf), str(src)], check=True, capture_output=True)
    r = subprocess.run([VB, "--profile", "--elf", str(elf), "--seconds", "0.01"], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 2, r.stderr
    errors = [x for x in r.stderr.splitlines() if x.startswith("pour_virtual_board:")]
    assert len(errors) == 1 and "--profile" in errors[0] and "symbols" in errors[0], r.stderr
    assert "Traceback" not in r.stderr and "profile:" not in r.stdout
