# SPDX-License-Identifier: MIT
"""pour_controller over LCM: answers, garbage on its channels, input timeout and clear, bad arguments."""
import random
import subprocess
import time

import pytest

from lcm_helpers import Bus, Proc, binary, msgs, url
from pour.lcm import channels

# The core's bits and modes (firmware/include/pour/faults.h) as the wire carries them. This file only runs
# programs (it also runs under ASan, where Python cannot load the sanitized libpoursim that names them).
FAULT_STALE_INPUT, FAULT_BAD_INPUT = 0x0001, 0x0004
MODE_RUN, MODE_FAULT = 1, 2


@pytest.fixture
def controller(build_dir):
    return binary(build_dir, "pour_controller")


def test_controller_answers_each_state_in_lockstep(controller):
    u = url(1)
    bus = Bus(u)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        answers = [bus.ask(k, theta=0.001 * k) for k in range(50)]
        assert c.stop() == 0
    assert [a.seq for a in answers] == list(range(50))
    assert all(a.mode == MODE_RUN and a.faults == 0 for a in answers)
    a = answers[-1]
    assert 2 <= a.n_actions <= 16 and 0 <= a.action < a.n_actions
    assert abs(sum(a.probs_q15[: a.n_actions]) - 32768) <= a.n_actions
    assert all(p == 0 for p in a.probs_q15[a.n_actions:])
    assert a.obs_q15[2] == 32767  # v_rotating = 1.0 saturates to the largest Q15
    assert "answers 50" in c.out and "dropped 0" in c.out


def test_controller_drops_and_counts_garbage_and_keeps_answering(controller):
    u = url(2)
    bus = Bus(u)
    bus.watch(channels.STATUS)
    rng = random.Random(5)
    good = bus.state(0)
    wrong_type = msgs.command_t().encode()
    garbage = [bytes(rng.randrange(256) for _ in range(rng.randrange(1, 200))) for _ in range(20)]
    garbage += [good[:n] for n in (0, 7, 8, 20, len(good) - 1)]  # truncated (fingerprint intact from 8 on)
    garbage += [good + b"\0", wrong_type]  # padded, and a foreign type on the state channel
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        assert bus.ask(0).seq == 0
        for g in garbage:
            bus.lc.publish(channels.SENSORS, g)
        for g in garbage[:5]:
            bus.lc.publish(channels.COMMAND, g)
        bus.lc.publish(channels.COMMAND, good)  # a state where a command belongs
        assert [bus.ask(k).seq for k in range(1, 6)] == list(range(1, 6))
        n_bad = len(garbage) + 6
        # A status at 10 Hz: wait for one that has seen everything sent.
        assert bus.wait_for(lambda: bus.got[channels.STATUS] and bus.last_status().messages_dropped == n_bad
                            and bus.last_status().states_received >= 6, 3.0)
        assert c.stop() == 0
    st = bus.last_status()
    assert st.states_received >= 6 and st.faults == 0
    assert f"dropped {n_bad}" in c.out


def test_controller_input_timeout_latches_fault_until_clear(controller):
    u = url(3)
    bus = Bus(u)
    bus.watch(channels.STATUS)
    args = [controller, "--io", f"lcm:{u}", "--lockstep", "--stall-ms", "50", "--input-timeout-ms", "20"]
    with Proc(args) as c:
        for k in range(20):
            assert bus.ask(k, theta=0.2).mode == MODE_RUN
        # Silence: after the stall the controller ticks on stale input, and the core's timeout trips.
        assert bus.wait_for(lambda: bus.got[channels.STATUS] and bus.last_status().faults & FAULT_STALE_INPUT, 5.0)
        st = bus.last_status()
        assert st.mode == MODE_FAULT and st.stale_ticks >= 20
        # States are back, but the fault is latched: safe torque, still FAULT, even for a new run (a reset
        # starts one afresh, and does not clear a fault).
        a = bus.ask(20, theta=0.2)
        assert a.mode == MODE_FAULT and a.faults & FAULT_STALE_INPUT and a.torque_q15 == 0
        bus.command(reset=True)
        bus.pump(0.05)
        assert bus.ask(0, episode=1, theta=0.2).mode == MODE_FAULT
        bus.command(clear_faults=True)
        bus.pump(0.05)
        a = bus.ask(1, episode=1, theta=0.2)
        assert a.faults == 0 and a.mode in (0, MODE_RUN)
        assert bus.ask(2, episode=1, theta=0.2).mode == MODE_RUN
        assert c.stop() == 0




@pytest.mark.parametrize("raw", [
    {"encoder": 1 << 17},                      # no count of the default 17-bit encoder
    {"encoder": -1},                           # a negative count (int32 on the wire)
    {"encoder": 2**31 - 1},
    {"scale_rotating_g": 30001},               # past the load cell's 30 kg
    {"scale_target_g": -2001},                 # a tared cell never reads 2 kg below zero
    {"scale_rotating_g": -2**31, "scale_target_g": 2**31 - 1},
])
def test_controller_latches_bad_input_on_an_impossible_sample(controller, raw):
    """A sample no sensor of the rig can give reaches the core as sent and is refused there: BAD_INPUT,
    FAULT, a message on stderr, and never torque from it."""
    u = url(7)
    bus = Bus(u)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        for k in range(10):
            assert bus.ask(k, theta=0.2).mode == MODE_RUN
        a = bus.ask(10, theta=0.2, **raw)
        assert a.mode == MODE_FAULT and a.faults & FAULT_BAD_INPUT, (raw, a.faults)
        a = bus.ask(11, theta=0.2)  # good samples again: the fault stays latched until a clear
        assert a.mode == MODE_FAULT and a.faults & FAULT_BAD_INPUT
        assert c.stop() == 0
    assert "fault 0x0004 latched at tick 11" in c.err


def test_controller_takes_the_encoder_resolution_it_is_given(controller):
    """--encoder-bits: a 20-bit encoder's counts are plausible there, and θ is read at that resolution."""
    u = url(8)
    bus = Bus(u)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep", "--encoder-bits", "20"]) as c:
        for k in range(5):
            a = bus.ask(k, theta=0.2, encoder=(1 << 18) + k)  # 1.57 rad at 20 bits; implausible at 17
            assert a.mode == MODE_RUN and a.faults == 0
        assert c.stop() == 0
    assert a.obs_q15[0] > 0


def test_controller_estop_zeroes_torque_and_latches(controller):
    u = url(4)
    bus = Bus(u)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        bus.ask(0, theta=0.5)
        bus.command(estop=True)
        bus.pump(0.05)
        a = bus.ask(1, theta=0.5)
        assert a.torque_q15 == 0 and a.mode == 3 and a.faults & 0x2
        bus.command(estop=False)
        bus.pump(0.05)
        assert bus.ask(2, theta=0.5).mode == MODE_FAULT
        bus.command(clear_faults=True)
        bus.pump(0.05)
        bus.ask(3, theta=0.5)
        assert bus.ask(4, theta=0.5).mode == MODE_RUN
        assert c.stop() == 0
    # The e-stop engaged the brake and cut the power once (hal_brake, hal_power of the Linux port).
    assert "brake_engagements 1 power_cuts 1" in c.out, c.out
    assert "mode RUN faults none (0x0000)" in c.out, c.out  # the exit line names the mode and the faults


def test_controller_drops_a_clear_sent_while_the_estop_is_held(controller):
    """docs/safety.md, transitions: "clear" with the e-stop still held, then the release, both before the next
    tick (lockstep: no sample between them), clears nothing; a clear after the release does."""
    u = url(9)
    bus = Bus(u)
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]) as c:
        bus.ask(0, theta=0.5)
        bus.command(estop=True)
        bus.pump(0.05)
        assert bus.ask(1, theta=0.5).mode == 3
        bus.command(estop=True, clear_faults=True)  # the clear arrives with the e-stop held
        bus.command(estop=False)
        bus.pump(0.05)
        a = bus.ask(2, theta=0.5)  # the held e-stop of the clear's own message still counts in this tick
        assert a.mode == 3 and a.torque_q15 == 0
        a = bus.ask(3, theta=0.5)
        assert a.mode == MODE_FAULT and a.faults & 0x2 and a.torque_q15 == 0
        bus.command(clear_faults=True)
        bus.pump(0.05)
        bus.ask(4, theta=0.5)
        assert bus.ask(5, theta=0.5).mode == MODE_RUN
        assert c.stop() == 0


def test_controller_real_time_ticks_without_states_and_counts(controller):
    u = url(5)
    bus = Bus(u)
    bus.watch(channels.STATUS)
    with Proc([controller, "--io", f"lcm:{u}", "--duration", "0.5"]) as c:
        assert c.p.wait(timeout=10) == 0
        c.stop()
    bus.pump(0.05)
    st = bus.last_status()
    assert st.timing == 0 and st.tick > 0 and st.stale_ticks == st.tick and st.mode == 0
    assert "ticks" in c.out and "overruns" in c.out


@pytest.mark.parametrize("argv, needle", [
    (["--io", "serial:/dev/ttyS0"], "unknown transport"),
    (["--io"], "--io needs"),
    (["--stall-ms", "0"], "--stall-ms needs an integer"),
    (["--stall-ms", "12x"], "--stall-ms needs an integer"),
    (["--duration", "-1"], "--duration needs"),
    (["--duration"], "--duration needs"),
    (["--input-timeout-ms", "70000"], "--input-timeout-ms needs"),
    (["--seed", "-3"], "--seed needs"),
    (["--encoder-bits", "7"], "--encoder-bits needs an integer in [8, 24]"),
    (["--encoder-bits", "25"], "--encoder-bits needs an integer in [8, 24]"),
    (["--frobnicate"], "unknown option"),
    (["--seed=-3"], "--seed needs"),  # --key=value as --key value
    (["--node", "3"], "--node goes with --channel"),
    (["stray"], "unexpected argument 'stray'"),
])
def test_controller_rejects_bad_arguments(controller, argv, needle):
    r = subprocess.run([controller, *argv], capture_output=True, text=True, timeout=10)
    assert r.returncode != 0
    assert needle in r.stderr


@pytest.mark.parametrize("io", [["--io", "lcm:nosuchprovider://x"], ["--lcm", "nosuchprovider://x"],
                                ["--lcm=nosuchprovider://x"]])
def test_controller_rejects_an_unusable_url(controller, io):
    r = subprocess.run([controller, *io], capture_output=True, text=True, timeout=10)
    assert r.returncode == 1
    assert "cannot open LCM" in r.stderr


def test_controller_stops_cleanly_on_sigint(controller):
    u = url(6)
    with Proc([controller, "--io", f"lcm:{u}"]) as c:
        time.sleep(0.3)
        assert c.stop() == 0
    assert c.out.startswith("pour_controller: ticks")
