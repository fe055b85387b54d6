# SPDX-License-Identifier: MIT
"""The whole bench in one guest: host_sim -> LCM -> can_bridge -> vcan0 -> pour_controller (Linux port,
SocketCAN), in lockstep. The trajectory must be the in-process run's, bit for bit (same seed)."""
from __future__ import annotations

import json
import re
import signal
import subprocess
import time

from canbus import BUILD_DIR, SOURCE_DIR, Bus

URL = "udpm://239.255.76.67:7681?ttl=0"
EPISODE_S = "3"
EPISODES = 2


def host_sim(*extra: str) -> subprocess.CompletedProcess:
    exe = BUILD_DIR / "bin" / "host_sim"
    argv = [str(exe), "--policy", str(SOURCE_DIR / "policy" / "weights.h"), "--set", f"episode_s={EPISODE_S}",
            "--episodes", str(EPISODES), "--seed", "4", *extra]
    return subprocess.run(argv, capture_output=True, text=True, timeout=600)


def vcan_tx_packets() -> int:
    """Frames vcan0 has carried (the kernel's interface statistics)."""
    out = subprocess.run(["ip", "-s", "-j", "link", "show", "vcan0"], capture_output=True, text=True, check=True)
    return int(json.loads(out.stdout)[0]["stats64"]["tx"]["packets"])


def stop(proc: subprocess.Popen) -> str:
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, f"{proc.args[0]} exit {proc.returncode}: {err}"
    return out + err


def test_lockstep_loop_over_can_is_bit_identical_to_in_process(tmp_path):
    # The in-process core restarted between the episodes as the controller on the bus is (--core-reset).
    ref = host_sim("--csv", str(tmp_path / "inproc.csv"), "--core-reset")
    assert ref.returncode == 0, ref.stderr

    bus = Bus()
    frames_before = vcan_tx_packets()
    ctl = subprocess.Popen([str(BUILD_DIR / "bin" / "pour_controller"), "--io", "can:vcan0", "--lockstep",
                            # The guest is slow between episodes (world reset): no stale ticks meanwhile.
                            "--stall-ms", "5000"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    bridge = subprocess.Popen([str(BUILD_DIR / "bin" / "can_bridge"), "--channel", "vcan0", "--lcm", URL],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        bus.wait_for("Heartbeat", timeout=10.0)
        t0 = time.monotonic()
        run = host_sim("--lcm", URL, "--csv", str(tmp_path / "can.csv"))
        wall = time.monotonic() - t0
    finally:
        bridge_out = stop(bridge)
        ctl_out = stop(ctl)
        bus.close()
    frames = vcan_tx_packets() - frames_before
    assert run.returncode == 0, run.stderr
    inproc = (tmp_path / "inproc.csv").read_text()
    over_can = (tmp_path / "can.csv").read_text()
    steps = EPISODES * int(EPISODE_S) * 1000
    assert len(inproc.splitlines()) == 1 + steps
    assert over_can == inproc  # every step: state, action, torque, reward
    summary = [x for x in run.stdout.splitlines() if x.startswith("summary")]
    assert summary == [x for x in ref.stdout.splitlines() if x.startswith("summary")]
    assert f"samples {steps} answers {steps} on_time {steps}" in run.stdout
    # host_sim resends a sample whose answer is slow (the guest is slow): every copy crosses and is answered.
    m = re.search(r"states (\d+) refused (\d+) torques (\d+) unmatched (\d+)", bridge_out)
    assert m, bridge_out
    sent, refused, torques, unmatched = map(int, m.groups())
    assert sent >= steps and refused == 0 and torques == sent and unmatched == 0, bridge_out
    m = re.search(r"answers (\d+) duplicates (\d+) dropped (\d+)", ctl_out)
    assert m and int(m.group(1)) == sent and int(m.group(1)) - int(m.group(2)) == steps and m.group(3) == "0", ctl_out
    assert frames >= 2 * steps  # the Sensors and the Torque frame of every step really crossed vcan0
    print(f"full loop over CAN (lockstep, in the user-mode Linux guest): {steps} steps in {wall:.2f} s "
          f"= {steps / wall:.0f} steps/s, {frames} frames")


def test_host_refuses_a_controller_with_another_policy_over_can(tmp_path):
    """The Identity frame carries the controller's policy hash through the bridge: host_sim, given another
    policy, refuses to pour with it (exit 4), as it does over LCM."""
    bus = Bus()
    ctl = subprocess.Popen([str(BUILD_DIR / "bin" / "pour_controller"), "--io", "can:vcan0", "--lockstep"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    bridge = subprocess.Popen([str(BUILD_DIR / "bin" / "can_bridge"), "--channel", "vcan0", "--lcm", URL],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        bus.wait_for("Identity", timeout=10.0)
        exe = BUILD_DIR / "bin" / "host_sim"
        run = subprocess.run([str(exe), "--policy", str(SOURCE_DIR / "policy" / "example_weights.h"), "--set",
                              "episode_s=0.2", "--lcm", URL], capture_output=True, text=True, timeout=300)
    finally:
        stop(bridge)
        stop(ctl)
        bus.close()
    assert run.returncode == 4, (run.returncode, run.stderr)
    assert "weights" in run.stderr
