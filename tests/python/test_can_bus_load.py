# SPDX-License-Identifier: MIT
"""Bus load of the pour CAN protocol: frame lengths, the worst-case stuffing bound (checked against real
bit streams with CRC-15 and stuffing), the total at 1 kHz under the 50 % bar, and bad input."""
from __future__ import annotations

import random
import subprocess
import sys

import pytest

from pour.can import bus_load as bl


def test_frame_bits_of_known_lengths():
    assert bl.frame_bits(8) == 135 and bl.frame_bits(8, stuffing=False) == 111
    assert bl.frame_bits(7) == 125 and bl.frame_bits(0) == 55 and bl.frame_bits(0, stuffing=False) == 47
    with pytest.raises(ValueError):
        bl.frame_bits(9)


def test_wire_bits_of_an_all_zero_frame():
    # id 0, 8 zero bytes: long runs of dominant bits, stuffed every 5
    assert bl.wire_bits(0, bytes(8)) > bl.frame_bits(8, stuffing=False) + 15
    with pytest.raises(ValueError):
        bl.wire_bits(0x800, b"")


def test_real_frames_never_exceed_the_worst_case_bound():
    rng = random.Random(6)
    worst_seen = {}
    for _ in range(3000):
        n = rng.randint(0, 8)
        data = bytes(rng.choice([0x00, 0xFF, rng.getrandbits(8)]) for _ in range(n))
        frame_id = rng.choice([0x000, 0x7FF, rng.getrandbits(11)])
        length = bl.wire_bits(frame_id, data)
        assert bl.frame_bits(n, stuffing=False) <= length <= bl.frame_bits(n)
        worst_seen[n] = max(worst_seen.get(n, 0), length)
    assert worst_seen[8] > bl.frame_bits(8, stuffing=False)  # stuffing does happen


def test_protocol_load_at_1khz_is_under_half_the_bus():
    rows = {r.name: r for r in bl.cyclic_messages()}
    # One 8-byte Sensors frame per tick carries the whole sample (no longer two state frames).
    assert set(rows) == {"Sensors", "Torque", "Heartbeat", "Identity", "DriveTelemetry"}
    assert rows["Sensors"].rate_hz == rows["Torque"].rate_hz == 1000.0
    assert rows["Heartbeat"].rate_hz == rows["Identity"].rate_hz == rows["DriveTelemetry"].rate_hz == 10.0
    total = sum(r.load for r in rows.values())
    assert total == pytest.approx(((135 + 125) * 1000 + 135 * 10 * 3) / 1e6)
    assert total < 0.5
    assert "26.4 % worst case" in bl.report(list(rows.values()))
    # The identity and drive-telemetry frames follow the heartbeat, whatever its period.
    fast = {r.name: r.rate_hz for r in bl.cyclic_messages(heartbeat_ms=20)}
    assert fast["Heartbeat"] == fast["Identity"] == fast["DriveTelemetry"] == 50.0


def test_cli_reports_and_rejects_bad_input(tmp_path):
    run = lambda *a: subprocess.run([sys.executable, "-m", "pour.can.bus_load", *a], capture_output=True,
                                    text=True, timeout=60)
    ok = run()
    assert ok.returncode == 0 and "bar 50 %: ok" in ok.stdout
    fast = run("--heartbeat-ms", "1")
    assert fast.returncode == 0 and "OVER" in fast.stdout
    for args in (["--heartbeat-ms", "0"], ["--dbc", str(tmp_path / "missing.dbc")]):
        r = run(*args)
        assert r.returncode == 2 and "pour-can-bus-load: error:" in r.stderr
    dump = tmp_path / "dump.log"
    dump.write_text("(1.0) vcan0 010#00FFFF0100003930\n(1.0) vcan0 012#00000000050100\n")
    r = run("--candump", str(dump))
    assert r.returncode == 0 and "2 frames over 1 ticks" in r.stdout
    dump.write_text("(1.0) vcan0 010#0000000000000000\n")
    r = run("--candump", str(dump))
    assert r.returncode == 2 and "no Torque frame" in r.stderr
    dump.write_text("(1.0) vcan0 910#00\n")
    r = run("--candump", str(dump))
    assert r.returncode == 2 and "not a classic 11-bit frame" in r.stderr
    bad = tmp_path / "bad.dbc"
    bad.write_text("garbage\n")
    r = run("--dbc", str(bad))
    assert r.returncode == 2 and "cannot read" in r.stderr
