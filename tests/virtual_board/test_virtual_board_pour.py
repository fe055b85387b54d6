# SPDX-License-Identifier: MIT
"""The flashed image in the closed loop (issue 37): pour_virtual_board --pour calibrates the drive on the empty
rig, the bucket is filled, the shipped policy pours in host_sim's world behind the gear, the host stops it when
host_sim's episode ends, and a reset of the board reads the stored calibration back; faults injected in the
models mid-pour end with the bucket held. One run per case, shared by its assertions (module-scoped fixtures):
the pour of seed 1, the pours of seeds 1..8 (3.5 s of RUN each) for the bars, one run per fault; each is a few
seconds of wall time (the board runs faster than real time here).

POUR_VB, POUR_ELF and POUR_HOST_SIM come from tests/virtual_board/CMakeLists.txt.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path

import pytest

VB = os.environ["POUR_VB"]
ELF = os.environ["POUR_ELF"]
HOST_SIM = os.environ["POUR_HOST_SIM"]
ROOT = Path(__file__).resolve().parents[2]
SEED = 1
FAULT_MS = 4000.0  # 560 ms into the pour (RUN at 3440 ms): the bucket at about 44 deg, moving, pouring


def run(*args: str, timeout: float = 240) -> subprocess.CompletedProcess[str]:
    return subprocess.run([VB, "--elf", ELF, *args], capture_output=True, text=True, timeout=timeout)


def number(pattern: str, text: str) -> float:
    m = re.search(pattern, text)
    assert m, f"no match for {pattern!r} in:\n{text}"
    return float(m.group(1))


def motor_model() -> tuple[float, float]:
    """R [ohm] and L [H] of host_sim's motor model, read from its source (the Plant's parameters)."""
    src = (ROOT / "host_sim/physics/motor_model.hpp").read_text()
    r = float(re.search(r"double r_phase = ([0-9.eE+-]+);", src).group(1))
    ld = float(re.search(r"double ld = ([0-9.eE+-]+),", src).group(1))
    return r, ld


@pytest.fixture(scope="module")
def pour(tmp_path_factory) -> tuple[subprocess.CompletedProcess[str], Path]:
    csv = tmp_path_factory.mktemp("pour") / "pour.csv"
    r = run("--pour", "--seed", str(SEED), "--csv", str(csv))
    assert r.returncode == 0, r.stderr + r.stdout
    return r, csv


def test_calibration_on_the_virtual_board_is_within_5_percent_of_the_motor_model(pour):
    out = pour[0].stdout
    r_model, l_model = motor_model()
    r = number(r"calibration: R ([0-9.]+) ohm", out)
    l_uh = number(r"L ([0-9.]+) uH \(model", out)
    assert abs(r / r_model - 1.0) <= 0.05, out
    assert abs(l_uh * 1e-6 / l_model - 1.0) <= 0.05, out
    assert number(r"pole pairs (\d+) \(model", out) == 8, out  # host_sim's motor model: pole_pairs = 8


def test_the_calibration_is_stored_and_read_back_after_a_reset(pour):
    r, _ = pour
    assert "reset at" in r.stderr and "the bench's reset (NRST)" in r.stderr, r.stderr
    line = next(x for x in r.stdout.splitlines() if x.startswith("read back after the reset"))
    # Stored 0 (POUR_CAN_CAL_OK): the boot found the block intact, as measured; Identity.InitStatus -8
    # (POUR_EALIGN; -5 would be uncalibrated): its electrical offset is not trusted after the reset
    assert "init status -8," in line and "stored 0," in line and "(as measured)" in line, line


def test_the_pour_ends_with_the_bucket_held(pour):
    out = pour[0].stdout
    assert number(r"poured ([0-9.]+) %, spilled", out) >= 98.0, out
    # the end as the read-back's reset left it: held (Held 1), RUN refused until a CalibrationStart (the drive's
    # CALIBRATION 0x0200: the offset is not trusted after a reset, POUR_EALIGN)
    assert re.search(r"end at .* brake engaged, mode FAULT, faults 0x0800, resets 0, drive faults 0x0200, held 1",
                     out), out


def test_the_pours_trajectory_follows_host_sims_full_drive_of_the_same_seed(pour):
    out, csv = pour[0].stdout, pour[1]
    h = subprocess.run([HOST_SIM, "--policy", str(ROOT / "policy/weights.h"), "--set", "drive=1", "--seed", str(SEED),
                        "--quiet", "--csv", str(csv.with_name("host_sim.csv"))],
                       capture_output=True, text=True, timeout=120)
    assert h.returncode == 0, h.stderr
    import csv as csvmod
    vb = {int(x["step"]): float(x["theta_rad"]) for x in csvmod.DictReader(csv.open())}
    ho = {int(x["step"]): float(x["theta_rad"]) for x in csvmod.DictReader(csv.with_name("host_sim.csv").open())}
    common = [k for k in vb if k in ho]
    assert len(common) >= 9990
    worst = max(abs(vb[k] - ho[k]) for k in common)
    assert worst < 0.02, f"largest |theta difference| {worst:.4f} rad"  # ~1.1 deg (0.4 .. 1.1 deg measured)


SEEDS = range(1, 9)


@pytest.fixture(scope="module")
def pours() -> dict[int, tuple[float, float]]:
    """Poured and spilled [%] of seeds 1..8 on the board: 3.5 s of RUN each (everything has landed by 3 s in
    both programs: the volumes at 3 s are those at 10 s on every one of these seeds)."""
    got = {}
    for seed in SEEDS:
        r = run("--pour", "--seed", str(seed), "--episode-s", "3.5", "--hold-s", "0.1")
        assert r.returncode == 0, r.stderr + r.stdout
        got[seed] = (number(r"poured ([0-9.]+) %, spilled", r.stdout), number(r"episode .* spilled ([0-9.]+) %", r.stdout))
    return got


def test_the_shipped_policy_pours_at_least_98_percent_and_spills_at_most_1_percent(pours):
    # Per pour the spill is a matter of one or two of the world's 150 particles (0.67 points each), and which
    # seeds spill one more flips with a microsecond's difference in when the torque reaches the current loop
    # (docs/virtual-board.md, "The pour against host_sim"): every pour >= 98 %, the spill <= 1 % on the mean.
    # Not per pour: host_sim's own full drive spills more than 1 % on 4 of seeds 1..40 (up to 2.67 %), and the
    # board's worst of these eight, 2.0 % on seed 8, lies within that spread.
    poured = [p for p, _ in pours.values()]
    spilled = [s for _, s in pours.values()]
    assert min(poured) >= 98.0, pours
    assert sum(spilled) / len(spilled) <= 1.0, pours


def test_the_pours_agree_with_host_sims_full_drive_of_the_same_seeds(pours):
    h = subprocess.run([HOST_SIM, "--policy", str(ROOT / "policy/weights.h"), "--set", "drive=1", "--seed", str(min(SEEDS)),
                        "--episodes", str(len(SEEDS)), "--json"], capture_output=True, text=True, timeout=300)
    assert h.returncode == 0, h.stderr
    hs = json.loads(h.stdout)
    poured = sum(p for p, _ in pours.values()) / len(pours)
    spilled = sum(s for _, s in pours.values()) / len(pours)
    # the 0.5 points, on the mean over the seeds (one seed's figure moves by a whole particle, 0.67)
    assert abs(poured - hs["poured_pct"]) <= 0.5 and abs(spilled - hs["spilled_pct"]) <= 0.5, (pours, hs)


def fault_run(*args: str) -> subprocess.CompletedProcess[str]:
    r = run("--pour", "--seed", str(SEED), *args)
    assert r.returncode == 0, r.stderr + r.stdout
    return r


def held(out: str) -> tuple[float, float]:
    """The angle where the fault began and how far the bucket moved after it [deg]; asserts the brake holds."""
    at = number(r"fault at [0-9.]+ ms: theta ([-0-9.]+) deg \(mode RUN\)", out)
    moved = number(r"moved at most ([0-9.]+) deg after it", out)
    end = number(r"end at [0-9.]+ ms: theta ([-0-9.]+) deg, brake engaged", out)
    assert at > 20.0, out  # mid-pour, not at rest
    assert moved < 10.0 and abs(end - at) < 10.0, out
    return at, moved


@pytest.fixture(scope="module")
def estop():
    return fault_run("--estop-at", str(FAULT_MS))


def test_the_estop_opened_mid_pour_ends_with_the_bucket_held(estop):
    held(estop.stdout)
    assert re.search(r"mode ESTOP, faults 0x0002", estop.stdout), estop.stdout
    # docs/safety.md: the e-stop's tick engages the brake and cuts the power (the next 1 kHz tick)
    assert number(r"PA15 low \(the power stage off\) ([0-9.]+) ms after", estop.stdout) < 1.5, estop.stdout


def test_a_phase_overcurrent_mid_pour_trips_the_break_and_ends_with_the_bucket_held():
    r = fault_run("--overcurrent-at", str(FAULT_MS))
    held(r.stdout)
    # the comparator's break cleared MOE within two PWM periods (50 us each: the low side's shunt carries the
    # phase current only while that low side conducts), long before the 1 kHz loop's next tick; then the
    # drive's fault (Heartbeat's Fault_Drive): the loop saw the cut
    assert number(r"TIM1 MOE 0 \(the bridge off\) ([0-9.]+) ms after the fault", r.stdout) < 0.101, r.stdout
    # docs/bringup.md: the power is cut only once the brake holds (its 20 ms here, --brake-ms)
    power = number(r"PA15 low \(the power stage off\) ([0-9.]+) ms after", r.stdout)
    assert power > number(r"the brake holding ([0-9.]+) ms after", r.stdout), r.stdout
    # ... and DriveTelemetry names it: POUR_DRIVE_FAULT_HW_OVERCURRENT (0x0002, pour/drive_faults.h), with
    # what the software saw of the same current
    m = re.search(r"end at .* mode FAULT, faults 0x0800, resets 0, drive faults 0x([0-9a-f]{4})", r.stdout)
    assert m and int(m.group(1), 16) & 0x0002, r.stdout


def test_a_missed_watchdog_refresh_mid_pour_resets_the_chip_and_ends_with_the_bucket_held():
    r = fault_run("--stall-core-at", str(FAULT_MS), "--stall-core-ms", "300")
    at = float(r.stderr.split("reset at ")[1].split(" ms")[0])
    assert "IWDG: no refresh within 10 ms" in r.stderr and FAULT_MS + 9.0 < at < FAULT_MS + 11.0, r.stderr
    held(r.stdout)
    # No restart on its own (IEC 60204-1 §9.2.5.4.1; docs/safety.md): the image boots held (Heartbeat's Held) and
    # does not trust the stored offset (the drive's CALIBRATION 0x0200, POUR_EALIGN): with the rig's samples
    # still coming it never enters RUN again, the brake engaged.
    assert re.search(r"end at .* brake engaged, mode FAULT, faults 0x0800, resets 1, drive faults 0x0200, held 1",
                     r.stdout), r.stdout
    assert "after the fault: RUN never re-entered" in r.stdout, r.stdout


def test_a_pour_after_a_reset_is_refused_until_the_offset_is_found_again():
    # The finding (docs/virtual-board.md): the stored electrical offset is the angle at TIM4's count 0, and
    # the image sets the count to 0 at every start (encoder_tim4.c), wherever the rotor stands. The calibration
    # leaves the shaft ~0.22 rad (~100 electrical degrees) from where it stood at power-on, so a pour after
    # a reset would commutate ~100 deg off (before the fix: TORQUE_SIGN 35 ms into RUN). Now the boot does not
    # trust the offset: RUN is refused by name (Identity.InitStatus -8, POUR_EALIGN; the drive's CALIBRATION
    # fault 0x0200 in DriveTelemetry) while the block stays stored (Stored 0), the bucket held upright.
    r = fault_run("--reset-before-pour")
    assert "init status -8, stored 0," in r.stdout, r.stdout
    elec = number(r"\(([0-9.]+) electrical deg from where it stood at power-on\)", r.stdout)
    assert 45.0 < elec < 315.0, r.stdout
    assert "pour: RUN at" not in r.stdout and "pour: RUN refused for 3 s, init status -8" in r.stdout, r.stdout
    assert re.search(r"end at .* theta -?0\.[0-9]+ deg, brake engaged, mode FAULT, faults 0x0800, resets 0, "
                     r"drive faults 0x0200, held 1", r.stdout), r.stdout


@pytest.mark.parametrize("fault", [["--corrupt-page", "63"], ["--ecc-page", "63"]], ids=["corrupt", "ecc"])
def test_a_bad_calibration_page_keeps_run_refused_by_name_and_the_bucket_held(fault):
    # The full bucket's rig sending, a ClearErrors at 300 ms (pour-bench clear): RUN is never entered, the
    # reason is named (CalibrationResult.Stored CORRUPT, Identity.InitStatus -5 = POUR_ECALIBRATION), the board
    # does not loop (no reset) and the brake holds the bucket upright. An empty page (EMPTY) for contrast.
    r = run("--world", "--read-calibration", "--clear-at", "300", "--seconds", "1", "--stop-on-reset", *fault)
    assert r.returncode == 0 and "reset at" not in r.stderr, r.stderr
    assert "calibration read: init status -5, stored 2 " in r.stdout, r.stdout
    assert "after ClearErrors at 300.0 ms: RUN never entered" in r.stdout, r.stdout
    assert re.search(r"end at 1000\.0 ms: theta -?0\.[0-9]+ deg, brake engaged, mode FAULT, faults 0x0800, resets 0", r.stdout), r.stdout


def test_an_empty_calibration_page_is_named_empty():
    r = run("--world", "--read-calibration", "--seconds", "0.3")
    assert r.returncode == 0 and "calibration read: init status -5, stored 1 " in r.stdout, r.stdout


def test_the_pour_is_deterministic(pour, tmp_path):
    # The same seed again, its first second: every step of the world identical to the fixture's run.
    csv = tmp_path / "again.csv"
    r = run("--pour", "--seed", str(SEED), "--episode-s", "1", "--hold-s", "0.1", "--csv", str(csv))
    assert r.returncode == 0, r.stderr
    again = csv.read_text().splitlines()
    first = pour[1].read_text().splitlines()[:len(again)]
    assert len(again) > 1000 and again == first


def test_the_world_in_the_loop_is_deterministic():
    a = run("--world", "--seed", "3", "--seconds", "0.3", "--print-can")
    b = run("--world", "--seed", "3", "--seconds", "0.3", "--print-can")
    assert a.returncode == 0 and a.stdout == b.stdout, a.stderr
    assert " tx 001 " in a.stdout


@pytest.mark.parametrize("args, says", [
    (["--world", "--pour"], "exclude each other"),
    (["--estop-at", "100"], "need --world, --empty-rig or --pour"),
    (["--empty-rig", "--world"], "exclude each other"),
    (["--world", "--overcurrent-at", "-1"], "--overcurrent-at must be"),
    (["--pour", "--overcurrent-at", "10", "--overcurrent-a", "0"], "--overcurrent-a must be"),
    (["--world", "--seed", "-1"], "--seed must be"),
    (["--world", "--seed", "x"], "bad number for --seed"),
    (["--reset-before-pour"], "needs --pour"),
    (["--read-calibration"], "need --world or --empty-rig"),
    (["--world", "--clear-at", "x"], "bad number for --clear-at"),
    (["--world", "--corrupt-page", "61"], "--corrupt-page must be 62 or 63"),
    (["--pour", "--brake-ms", "-1"], "--brake-ms must be"),
    (["--world", "--csv", "x.csv"], "--csv needs --pour"),
    (["--pour", "--episode-s", "0"], "--episode-s must be"),
])
def test_bad_rig_options_are_refused_in_one_line(args, says):
    r = run(*args, timeout=30)
    assert r.returncode == 2 and says in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_an_unwritable_csv_fails_the_run_by_name(tmp_path):
    target = tmp_path / "no-such-dir" / "pour.csv"
    r = run("--pour", "--episode-s", "0.05", "--hold-s", "0.05", "--csv", str(target))
    assert r.returncode == 1 and f"cannot write {target}" in r.stderr, r.stderr
    assert not target.parent.exists()
