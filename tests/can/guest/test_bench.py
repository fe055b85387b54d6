# SPDX-License-Identifier: MIT
"""Bench bring-up end to end over vcan0, as a user runs it: pour-bench (scan, info, config set/save, faults,
e-stop, clear, plot, log) against pour_controller --io can:vcan0,params=FILE, with host_sim pouring as the plant through
can_bridge; the controller restarted, its saved parameters still in force. Then the bad cases
on a real bus: no node, two nodes on one id, a refused write, a node that stops answering mid-command."""
from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

from canbus import BUILD_DIR, SOURCE_DIR, Controller
from pour.bench import node as bn
from pour.policy import weights_h

URL = "udpm://239.255.76.67:7685?ttl=0"
WEIGHTS = SOURCE_DIR / "policy" / "weights.h"
# The guest cannot keep a 1 kHz real-time loop fed (host_sim makes ~300 samples/s in it): plant and controller
# run in lockstep, one tick per sample, so the controller answers parameter requests at the plant's pace.
LOCKSTEP = ("--lockstep", "--stall-ms", "5000")


def bench(*argv: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pour.bench.cli", "--iface", "vcan0", "--timeout", "2", *argv],
                          capture_output=True, text=True, timeout=timeout)


def ok(*argv: str) -> str:
    r = bench(*argv)
    assert r.returncode == 0, (argv, r.stdout, r.stderr)
    return r.stdout


def refused(*argv: str, timeout: float = 60) -> str:
    r = bench(*argv, timeout=timeout)
    assert r.returncode == 1, (argv, r.stdout, r.stderr)
    assert r.stderr.startswith("pour-bench: error: "), r.stderr
    return r.stderr


def stop(proc: subprocess.Popen) -> str:
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    return out + err


def test_bring_up_with_host_sim_as_the_plant(tmp_path):
    params = tmp_path / "params.bin"
    policy_hash = weights_h.parse_weights_h(WEIGHTS).content_hash
    ctl = Controller(*LOCKSTEP, io=f"can:vcan0,params={params}")
    bridge = subprocess.Popen([str(BUILD_DIR / "bin" / "can_bridge"), "--iface", "vcan0", "--lcm", URL],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    plant = subprocess.Popen([str(BUILD_DIR / "bin" / "host_sim"), "--policy", str(WEIGHTS), "--lcm", URL,
                              "--lcm-timeout-ms", "60000", "--set", "episode_s=300"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out = ok("scan")
        assert f"node 0: mode " in out and f"policy 0x{policy_hash:08x}" in out, out
        out = ok("info")
        assert f"policy 0x{policy_hash:08x}" in out and "firmware " in out and "init status 0" in out, out
        # The plant's samples put the controller in RUN: no write mid-run, the reason on the bus.
        with bn.Bench("vcan0") as b:
            n = b.node(0)
            n.wait_mode({"RUN"}, timeout=20)
            with pytest.raises(bn.ParamRefused) as e:
                n.set("omega_max", 1500000)
            assert e.value.result == "BUSY" and e.value.param == "omega_max"
        # The e-stop (a level): writes refused while it is asserted, accepted in FAULT after the release.
        assert "mode ESTOP" in ok("estop")
        # Commands the controller refuses say so (the heartbeat's Refused count), and change nothing.
        assert "refused Stop in ESTOP" in refused("stop")
        assert "refused ClearErrors in ESTOP" in refused("--weights", str(WEIGHTS), "--yes", "clear")
        assert "BUSY" in refused("config", "set", "omega_max", "1500000")
        assert "mode FAULT" in ok("estop", "--release")
        assert ok("config", "set", "omega_max", "1500000") == "omega_max 1500000\n"
        assert ok("config", "set", "stop_timeout", "4000") == "stop_timeout 4000\n"
        assert "OUT_OF_RANGE" in refused("config", "set", "encoder_bits", "30")
        assert "INCONSISTENT" in refused("config", "set", "theta_min", "2400000")  # above theta_max
        assert "no parameter 'nosuch'" in refused("config", "get", "nosuch")
        assert "parameters saved" in ok("config", "save")
        assert params.stat().st_size > 0
        out = ok("faults")
        assert "mode FAULT" in out and "EStop" in out, out
        # The live plot of the running bus, drawn off-screen here (no display in the guest).
        png = tmp_path / "plot.png"
        out = ok("plot", "--seconds", "2", "--no-window", "--png", str(png))
        assert "frames of node 0" in out and png.read_bytes()[:4] == b"\x89PNG", out
        # Motion commands check the policy and want a confirmation.
        r = bench("clear")
        assert r.returncode == 2 and "--expect-hash" in r.stderr, r.stderr
        assert "not the expected" in refused("--expect-hash", "0x12345678", "--yes", "clear")
        assert "confirm with --yes" in refused("--weights", str(WEIGHTS), "clear")

        # A restart of the controller: the saved values are the ones in force.
        log = stop(ctl.proc)
        assert "parameter request 0x0a (parameter 4) refused: busy (not in IDLE or FAULT)" in log, log
        assert "parameter request 0x0a (parameter 16) refused: out of range" in log, log
        ctl = Controller(*LOCKSTEP, io=f"can:vcan0,params={params}")
        out = ok("config", "get", "omega_max", "stop_timeout", "encoder_bits")
        assert out == "omega_max 1500000\nstop_timeout 4000\nencoder_bits 17\n", out
        out = ok("--weights", str(WEIGHTS), "--yes", "clear")
        assert "faults none" in out, out
        assert "mode ESTOP" in ok("estop")
        out = ok("faults")
        assert "mode ESTOP" in out and "EStop" in out, out
        log_file = tmp_path / "bus.log"
        out = ok("log", str(log_file), "--seconds", "1")
        lines = log_file.read_text().splitlines()
        assert lines and all(" vcan0 " in x for x in lines[:10]), lines[:3]
        assert any(" 001#" in x for x in lines) and any(" 010#" in x for x in lines)  # heartbeats, samples
    finally:
        stop(plant)
        stop(bridge)
        ctl_out = stop(ctl.proc)
    assert "pour_controller: parameters from" in ctl_out, ctl_out


def test_a_bus_without_a_node_is_an_error():
    err = refused("scan")
    assert "no node on vcan0" in err
    err = refused("info")
    assert "node 0 did not answer with a heartbeat" in err and "never heard" in err


def test_two_nodes_on_one_id_are_an_error():
    a = Controller(io="can:vcan0,node=3")
    b = Controller(io="can:vcan0,node=3")
    try:
        err = refused("scan", timeout=60)
    finally:
        a.stop()
        b.stop()
    assert "two nodes answer on id 3" in err, err


def test_a_node_that_stops_answering_times_out_with_its_last_state(tmp_path):
    ctl = Controller(io=f"can:vcan0,params={tmp_path / 'p.bin'}")
    try:
        with bn.Bench("vcan0") as b:
            n = b.node(0)
            assert n.info().mode == "IDLE"
            assert n.get("omega_max") == 2000000
            ctl.proc.send_signal(signal.SIGSTOP)  # the process hangs between two requests
            with pytest.raises(bn.NodeTimeout) as e:
                n.set("omega_max", 1000000, timeout=1.0)
        msg = str(e.value)
        assert "node 0 did not answer ParamWrite(omega_max) within 1 s (node 0: mode IDLE" in msg, msg
        assert "last heartbeat" in msg and e.value.last is not None and e.value.last.mode == "IDLE"
    finally:
        ctl.proc.send_signal(signal.SIGCONT)
        ctl.stop()


def test_save_without_storage_is_refused():
    ctl = Controller()
    try:
        assert "NO_STORAGE" in refused("config", "save")
        assert "NO_SAMPLE" in refused("tare")
    finally:
        ctl.stop()
