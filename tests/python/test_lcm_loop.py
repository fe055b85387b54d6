# SPDX-License-Identifier: MIT
"""The closed loop as two processes over LCM (udpm on loopback): bit-identical to the in-process run in
lockstep, robust to garbage on the torque channel, a clear error when nobody answers."""
import random
import subprocess
import threading

import pytest

from lcm_helpers import Bus, Proc, binary, compiled_weights, url
from pour.lcm import channels

STEPS = "1500"


@pytest.fixture
def tools(build_dir):
    return binary(build_dir, "pour_controller"), binary(build_dir, "lcm_loop_driver")


def run(argv, timeout=120):
    r = subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=timeout)
    return r


def hash_of(stdout: str) -> str:
    line = [x for x in stdout.splitlines() if x.startswith("trajectory_hash ")]
    assert line, stdout
    return line[-1].split()[1]


def stats_of(stdout: str) -> dict:
    line = [x for x in stdout.splitlines() if x.startswith("lcm ")][-1]
    words = line.split()[2:]
    return {k: float(int(v, 16) if v.startswith("0x") else v) for k, v in zip(words[0::2], words[1::2])}


def test_lockstep_loop_is_bit_identical_to_in_process(tools, tmp_path):
    controller, driver = tools
    ref = run([driver, "--mode", "inproc", "--steps", STEPS, "--episodes", "2", "--seed", "7",
               "--trace", tmp_path / "inproc.txt"])
    assert ref.returncode == 0, ref.stderr
    u = url(11)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        r = run([driver, "--mode", "lcm", "--url", u, "--steps", STEPS, "--episodes", "2", "--seed", "7",
                 "--trace", tmp_path / "lcm.txt"])
        assert c.stop() == 0
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "lcm.txt").read_text() == (tmp_path / "inproc.txt").read_text()
    assert hash_of(r.stdout) == hash_of(ref.stdout)
    s = stats_of(r.stdout)
    assert s["samples"] == 2 * int(STEPS) and s["on_time"] == s["samples"] and s["missing"] == 0
    assert "resets 2" in c.out
    # The policy acted: some torque was non-zero.
    assert any(line.split()[-1] != "0" for line in (tmp_path / "lcm.txt").read_text().splitlines())


def test_host_drops_garbage_on_the_torque_channel_and_stays_identical(tools):
    controller, driver = tools
    ref = run([driver, "--mode", "inproc", "--steps", "800", "--seed", "3"])
    u = url(12)
    bus = Bus(u)
    stop = threading.Event()
    sent = [0]

    def spam() -> None:
        rng = random.Random(9)
        while not stop.is_set():
            bus.lc.publish(channels.TORQUE, bytes(rng.randrange(256) for _ in range(rng.randrange(1, 120))))
            sent[0] += 1
            stop.wait(0.002)

    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        t = threading.Thread(target=spam)
        t.start()
        try:
            r = run([driver, "--mode", "lcm", "--url", u, "--steps", "800", "--seed", "3"])
        finally:
            stop.set()
            t.join()
        c.stop()
    assert r.returncode == 0, r.stderr
    assert hash_of(r.stdout) == hash_of(ref.stdout)
    s = stats_of(r.stdout)
    assert 0 < s["dropped"] <= sent[0]


def test_lockstep_without_controller_fails_naming_the_channel(tools):
    _, driver = tools
    r = run([driver, "--mode", "lcm", "--url", url(13), "--steps", "10", "--answer-timeout-ms", "300"])
    assert r.returncode == 3
    assert "POUR_TORQUE" in r.stderr and "seq 0" in r.stderr


def test_real_time_loop_counts_every_state(tools):
    controller, driver = tools
    u = url(14)
    with Proc([controller, "--io", f"lcm:{u}"]) as c:
        r = run([driver, "--mode", "lcm", "--url", u, "--realtime", "--steps", "500"])
        c.stop()
    assert r.returncode == 0, r.stderr
    s = stats_of(r.stdout)
    # No timing asserted: only that every sample is accounted for.
    assert s["samples"] == 500
    assert s["on_time"] + s["late"] + s["missing"] == 500
    assert s["answers"] == s["on_time"] + s["late"]


def test_real_time_without_controller_carries_on_with_safe_torque(tools):
    _, driver = tools
    r = run([driver, "--mode", "lcm", "--url", url(15), "--realtime", "--steps", "200"])
    assert r.returncode == 0, r.stderr
    s = stats_of(r.stdout)
    assert s["missing"] == 200 and s["safe_ticks"] == 200


@pytest.mark.parametrize("argv, needle", [
    (["--mode", "tcp"], "--mode must be"),
    (["--mode", "lcm", "--steps", "0"], "--steps needs"),
    (["--mode", "lcm", "--answer-timeout-ms", "x"], "--answer-timeout-ms needs"),
    (["--mode", "lcm", "--url", "nosuchprovider://x"], "cannot open LCM"),
])
def test_driver_rejects_bad_arguments(tools, argv, needle):
    _, driver = tools
    r = run([driver, *argv])
    assert r.returncode != 0 and needle in r.stderr


# ---- host_sim itself: the README's pour, as two processes ----

def host_sim_args(build_dir, *extra):
    return ["--policy", compiled_weights(build_dir), "--set", "episode_s=3", "--episodes", "2",
            "--seed", "4", *extra]


def test_host_sim_lockstep_over_lcm_is_bit_identical_to_in_process(build_dir, source_dir, tmp_path):
    host_sim = binary(build_dir, "host_sim")
    controller = binary(build_dir, "pour_controller")
    # In process, the core is restarted between the episodes as the linked controller is (--core-reset):
    # ClearErrors, Stop and Reset in the second episode's first tick, from the torque still on the wire.
    ref = run([host_sim, *host_sim_args(build_dir, "--csv", tmp_path / "inproc.csv", "--core-reset")])
    assert ref.returncode == 0, ref.stderr
    u = url(16)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        r = run([host_sim, *host_sim_args(build_dir, "--lcm", u, "--csv", tmp_path / "lcm.csv")])
        assert c.stop() == 0
    assert r.returncode == 0, r.stderr
    inproc, lcm_csv = (tmp_path / "inproc.csv").read_text(), (tmp_path / "lcm.csv").read_text()
    assert len(inproc.splitlines()) == 1 + 2 * 3000
    assert lcm_csv == inproc  # every step: state, action, torque, reward
    assert "lcm lockstep: samples 6000 answers 6000 on_time 6000" in r.stdout
    summary = [x for x in r.stdout.splitlines() if x.startswith("summary")]
    assert summary == [x for x in ref.stdout.splitlines() if x.startswith("summary")]
    assert "answers 6000" in c.out and "resets 2" in c.out


def test_host_sim_lockstep_without_controller_exits_3_naming_the_channel(build_dir, source_dir, tmp_path):
    host_sim = binary(build_dir, "host_sim")
    csv = tmp_path / "run.csv"
    r = run([host_sim, *host_sim_args(build_dir, "--lcm", url(17), "--lcm-timeout-ms", "300", "--csv", csv)])
    assert r.returncode == 3
    assert "no answer on POUR_TORQUE to POUR_SENSORS seq 0" in r.stderr
    # The link reports the failure to host_sim, which ends the run: no CSV, no temporary left behind.
    assert list(tmp_path.iterdir()) == []


def test_host_sim_real_time_without_controller_carries_on_with_safe_torque(build_dir, source_dir):
    host_sim = binary(build_dir, "host_sim")
    r = run([host_sim, "--policy", compiled_weights(build_dir), "--set", "episode_s=0.3",
             "--lcm", url(18), "--realtime"])
    assert r.returncode == 0, r.stderr
    line = [x for x in r.stdout.splitlines() if x.startswith("lcm realtime")][0]
    assert "samples 300 answers 0" in line and "missing 300" in line and "safe_ticks 300" in line


@pytest.mark.parametrize("argv, needle", [
    (["--baseline", "hand", "--lcm"], "--lcm goes with --policy FILE or alone"),
    (["--core-reset", "--lcm"], "--core-reset goes with --policy FILE and no --lcm"),
    (["--baseline", "hand", "--core-reset"], "--core-reset goes with --policy FILE and no --lcm"),
    (["--bench", "--lcm"], "--lcm goes with --policy FILE or alone"),
    (["--baseline", "hand", "--realtime"], "--realtime needs --lcm"),
    (["--lcm", "--lcm-timeout-ms", "0"], "--lcm-timeout-ms wants an integer"),
    (["--lcm", "--lcm-timeout-ms"], "--lcm-timeout-ms needs a value"),
    (["--lcm", "nosuchprovider://x"], "cannot open LCM"),
])
def test_host_sim_rejects_bad_lcm_arguments(build_dir, argv, needle):
    r = run([binary(build_dir, "host_sim"), *argv])
    assert r.returncode != 0 and needle in r.stderr


def test_host_sim_refuses_a_controller_with_other_weights(build_dir, source_dir):
    """host_sim --policy X must not pour silently with a controller built from other weights."""
    other = source_dir / "tests" / "golden" / "example_weights_2.h"
    assert other.read_text() != compiled_weights(build_dir).read_text()
    u = url(19)
    with Proc([binary(build_dir, "pour_controller"), "--io", f"lcm:{u}", "--lockstep"]):
        r = run([binary(build_dir, "host_sim"), "--policy", other, "--set", "episode_s=0.2", "--lcm", u])
    assert r.returncode == 4
    assert "pour_controller runs weights with content hash" in r.stderr and "POUR_WEIGHTS" in r.stderr
