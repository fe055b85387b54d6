# SPDX-License-Identifier: MIT
"""Bad input to the CAN entry points fails fast with a message and a non-zero exit, on a kernel with or
without CAN: pour_controller --io can:..., can_bridge."""
from __future__ import annotations

import struct
import subprocess
import zlib
from pathlib import Path

import pytest

from conftest import BUILD_DIR


def exe(name: str) -> Path:
    p = BUILD_DIR / "bin" / name
    if p.exists():
        return p
    raise FileNotFoundError(f"{name} not built in {BUILD_DIR}")


def run(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=30)


@pytest.mark.parametrize("spec, needle", [
    ("can:", "interface name of 1..15 characters"),
    ("can:averyveryverylongname0", "interface name of 1..15 characters"),
    ("can:vcan0,node=64", "node needs an integer in [0, 63]"),
    ("can:vcan0,node=-1", "node needs an integer in [0, 63]"),
    ("can:vcan0,heartbeat-ms=0", "heartbeat-ms needs an integer in [1, 65535]"),
    ("can:vcan0,watchdog-ms=x", "watchdog-ms needs an integer in [1, 65535]"),
    ("can:vcan0,speed=1", "unknown key 'speed'"),
    ("can:vcan0,node", "'node' is not key=value"),
    ("can:vcan0,drive=board", "drive can only be 'sim'"),
    ("can:vcan0,drive=sim", "run pour_controller_sim"),  # the simulated drive is the twin's, not this build's
])
def test_controller_rejects_bad_can_specs(spec, needle):
    r = run(exe("pour_controller"), "--io", spec)
    assert r.returncode != 0
    assert needle in r.stderr


def test_controller_without_the_interface_says_so():
    # Host kernel without CAN: "no CAN support"; a guest without that interface: "no such CAN interface".
    r = run(exe("pour_controller"), "--io", "can:nosuchcan0")
    assert r.returncode == 1
    assert "no CAN support" in r.stderr or "no such CAN interface" in r.stderr


def params_blob(values: dict[int, int], version: int = 1) -> bytes:
    """A parameter file as firmware/include/pour/params.h lays it out (magic, version, count, records,
    CRC-32), to hand the controller files it must refuse."""
    body = b"PPRM" + struct.pack("<HH", version, len(values))
    body += b"".join(struct.pack("<Bi", k, v) for k, v in sorted(values.items()))
    return body + struct.pack("<I", zlib.crc32(body))


@pytest.mark.parametrize("content, needle", [
    (b"", "truncated"),
    (params_blob({4: 1500000})[:-1], "truncated"),
    (b"XXXX" + params_blob({4: 1500000})[4:], "bad magic"),
    (params_blob({4: 1500000}, version=2), "unsupported layout version"),
    (params_blob({4: 1500000})[:-1] + b"\0", "CRC mismatch"),
    (params_blob({16: 30}), "parameter 16 (encoder_bits)"),
    (params_blob({99: 1}), "parameter 99 (no such parameter)"),
    (params_blob({17: 200000}), "parameter 17 (encoder_zero)"),
])
def test_controller_refuses_a_bad_parameter_file_at_start(tmp_path, content, needle):
    f = tmp_path / "params.bin"
    f.write_bytes(content)
    r = run(exe("pour_controller"), "--io", f"can:vcan0,params={f}")
    assert r.returncode == 1, r.stderr
    assert f"parameter file {f}" in r.stderr and needle in r.stderr, r.stderr
    assert f.read_bytes() == content  # never rewritten


def test_controller_refuses_a_parameter_set_the_core_refuses(tmp_path):
    f = tmp_path / "params.bin"
    f.write_bytes(params_blob({2: 100000, 3: 50000}))  # theta_min above theta_max: each in range
    r = run(exe("pour_controller"), "--io", f"can:vcan0,params={f}")
    assert r.returncode == 1
    assert f"parameter file {f}: the core refuses its configuration" in r.stderr, r.stderr


@pytest.mark.parametrize("argv, needle", [
    ([], "--channel CHANNEL is required"),
    (["--channel", "vcan0", "--node", "64"], "--node needs an integer in [0, 63]"),
    (["--channel", "vcan0", "--n-actions", "1"], "--n-actions needs an integer in [2, 16]"),
    (["--channel", "vcan0", "--frobnicate"], "unknown option"),
    (["--channel"], "--channel needs a value"),
    (["--channel=vcan0", "--node=64"], "--node needs an integer in [0, 63]"),  # --key=value as --key value
    (["--channel", "vcan0", "stray"], "unexpected argument 'stray'"),
])
def test_bridge_rejects_bad_arguments(argv, needle):
    r = run(exe("can_bridge"), *argv)
    assert r.returncode == 2
    assert needle in r.stderr


@pytest.mark.parametrize("iface", [["--channel", "nosuchcan0"], ["--channel=nosuchcan0"]])
def test_bridge_without_the_interface_says_so(iface):
    r = run(exe("can_bridge"), *iface)
    assert r.returncode == 1
    assert "no CAN support" in r.stderr or "no such CAN interface" in r.stderr


@pytest.mark.parametrize("argv", [["--channel", "nosuchcan0"], ["--channel=nosuchcan0", "--node=3"]])
def test_controller_takes_the_bridges_can_flags(argv):
    """pour_controller --channel CHANNEL [--node N] is its --io can:CHANNEL[,node=N]."""
    r = run(exe("pour_controller"), *argv)
    assert r.returncode == 1
    assert "no CAN support" in r.stderr or "no such CAN interface" in r.stderr


@pytest.mark.parametrize("program", ["can_bridge", "pour_controller"])
def test_option_names_are_python_cans(program):
    """--channel and --interface as python-can and pour-bench name them; the old --iface says what to type."""
    r = run(exe(program), "--iface", "vcan0")
    assert r.returncode == 2 and f"{program}: --iface is now --channel" in r.stderr and "--channel vcan0" in r.stderr
    r = run(exe(program), "--channel", "vcan0", "--interface", "pcan")
    assert r.returncode == 2 and "only socketcan is supported" in r.stderr, r.stderr
    r = run(exe(program), "--help")
    assert r.returncode == 0 and "--channel" in r.stdout and "--interface" in r.stdout and "--iface" not in r.stdout


def test_bridge_help_names_the_channels():
    r = run(exe("can_bridge"), "--help")
    assert r.returncode == 0 and "POUR_SENSORS" in r.stdout and "POUR_TORQUE" in r.stdout
