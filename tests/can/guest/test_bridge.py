# SPDX-License-Identifier: MIT
"""can_bridge on vcan0 as LCM tools see it: POUR_SENSORS in, POUR_TORQUE and POUR_STATUS out from a controller
that only speaks CAN, POUR_COMMAND e-stop and clear reaching it, garbage on LCM dropped and counted, readings
the Sensors frame cannot carry refused with a message."""
from __future__ import annotations

import random
import re
import signal
import subprocess
import time

import lcm
import pytest

from canbus import BUILD_DIR, LIQUID_G, SOURCE_DIR, Plant, encoder_count
from pour.lcm import channels, messages

msgs = messages.load()
URL = "udpm://239.255.76.67:7683?ttl=0"


class Host:
    """A minimal LCM host: sends sensor samples, collects the answers and statuses the bridge publishes."""

    def __init__(self) -> None:
        self.lc = lcm.LCM(URL)
        self.torques: list = []
        self.statuses: list = []
        self.plant = Plant()
        self.lc.subscribe(channels.TORQUE, lambda ch, data: self.torques.append(msgs.torque_t.decode(data)))
        self.lc.subscribe(channels.STATUS, lambda ch, data: self.statuses.append(msgs.controller_status_t.decode(data)))

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.lc.handle_timeout(10)

    @staticmethod
    def encode(seq: int, episode: int, encoder: int, scale_rotating_g: int = LIQUID_G) -> bytes:
        m = msgs.sensor_sample_t()
        m.utime, m.seq, m.episode = 1000 * seq + 11, seq, episode
        m.encoder, m.scale_rotating_g, m.scale_target_g = encoder, scale_rotating_g, 0
        return m.encode()

    def state(self, seq: int, episode: int = 7):
        theta_urad, _ = self.plant.advance()
        self.lc.publish(channels.SENSORS, self.encode(seq, episode, encoder_count(theta_urad)))
        end = time.monotonic() + 5.0
        while time.monotonic() < end:
            self.lc.handle_timeout(20)
            hits = [t for t in self.torques if t.seq == seq and t.episode == episode]
            if hits:
                self.plant.torque_q15 = hits[-1].torque_q15
                return hits[-1]
        raise AssertionError(f"no POUR_TORQUE answer to seq {seq}")

    def command(self, estop: bool, clear: bool) -> None:
        c = msgs.command_t()
        c.utime, c.estop, c.clear_faults = 0, estop, clear
        self.lc.publish(channels.COMMAND, c.encode())

    def status(self, pred, timeout: float = 3.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.lc.handle_timeout(20)
            hits = [s for s in self.statuses if pred(s)]
            if hits:
                return hits[-1]
        raise AssertionError("no POUR_STATUS matching the condition")


def test_bridge_makes_a_can_controller_look_like_an_lcm_one():
    ctl = subprocess.Popen([str(BUILD_DIR / "bin" / "pour_controller"), "--io", "can:vcan0,heartbeat-ms=20",
                            "--lockstep"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    bridge = subprocess.Popen([str(BUILD_DIR / "bin" / "can_bridge"), "--channel", "vcan0", "--lcm", URL],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    host = Host()
    try:
        host.status(lambda s: True, timeout=10.0)  # heartbeats arrive as POUR_STATUS
        answers = [host.state(seq) for seq in range(30)]
        a = answers[-1]
        assert (a.seq, a.episode, a.state_utime) == (29, 7, 29 * 1000 + 11)  # restored by the bridge
        assert a.mode == 1 and a.torque_q15 != 0
        weights = (SOURCE_DIR / "policy" / "weights.h").read_text()
        tau_max_nm = int(re.search(r"#define POUR_WEIGHTS_TAU_MAX_MNM (\d+)", weights).group(1)) / 1000
        assert a.torque == pytest.approx(a.torque_q15 / 32768 * tau_max_nm)  # the scale the Identity frame announced
        weights_hash = int(re.search(r"#define POUR_WEIGHTS_CONTENT_HASH (0x[0-9a-fA-F]+)u", weights).group(1), 16)
        assert a.weights_hash & 0xFFFFFFFF == weights_hash
        assert host.status(lambda s: s.mode == 1).faults == 0

        host.command(estop=True, clear=False)
        time.sleep(0.05)
        a = host.state(30)
        assert a.torque_q15 == 0 and a.mode == 3  # zero torque on the next tick
        s = host.status(lambda s: s.mode == 3 and s.faults & 0x2)
        assert s.messages_dropped == 0

        host.command(estop=False, clear=True)
        time.sleep(0.05)
        answers = [host.state(seq) for seq in range(31, 61)]
        assert answers[-1].mode == 1 and answers[-1].torque_q15 != 0
        host.status(lambda s: s.mode == 1 and s.faults == 0)

        rng = random.Random(5)  # garbage on our channels: decoded by nobody, counted by the bridge
        for _ in range(5):
            host.lc.publish(channels.SENSORS, bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 40))))
            host.lc.publish(channels.COMMAND, b"\x00\x01")
        # A reading the Sensors frame cannot carry (±32767 g): refused by the bridge, never wrapped into
        # another value; no answer comes to it.
        host.lc.publish(channels.SENSORS, Host.encode(61, 7, 0, scale_rotating_g=40000))
        host.pump(0.2)
        assert not [t for t in host.torques if t.seq == 61]
        assert host.state(61).seq == 61
    finally:
        bridge.send_signal(signal.SIGINT)
        out, err = bridge.communicate(timeout=20)
        ctl.send_signal(signal.SIGINT)
        ctl.communicate(timeout=20)
    assert bridge.returncode == 0, err
    m = re.search(r"states (\d+) refused (\d+) torques (\d+) unmatched (\d+) heartbeats (\d+) identities (\d+) "
                  r"frames_dropped (\d+) commands (\d+) lcm_dropped (\d+)", out)
    assert m, out
    states, refused, torques, unmatched, heartbeats, identities, frames_dropped, commands, lcm_dropped = map(
        int, m.groups())
    assert states == torques == 62 and refused == 1 and unmatched == frames_dropped == 0
    assert "POUR_SENSORS seq 61 not sent: scale_rotating_g outside -32767 .. 32767 g" in err
    assert heartbeats > 0 and identities > 0 and commands == 2 and lcm_dropped == 10
