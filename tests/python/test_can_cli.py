# SPDX-License-Identifier: MIT
"""Bad input to the CAN entry points fails fast with a message and a non-zero exit, on a kernel with or
without CAN: pour_controller --io can:..., can_bridge."""
from __future__ import annotations

import subprocess
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


@pytest.mark.parametrize("argv, needle", [
    ([], "--iface IFACE is required"),
    (["--iface", "vcan0", "--node", "64"], "--node needs an integer in [0, 63]"),
    (["--iface", "vcan0", "--n-actions", "1"], "--n-actions needs an integer in [2, 16]"),
    (["--iface", "vcan0", "--frobnicate"], "unknown option"),
    (["--iface"], "--iface needs a value"),
    (["--iface=vcan0", "--node=64"], "--node needs an integer in [0, 63]"),  # --key=value as --key value
    (["--iface", "vcan0", "stray"], "unexpected argument 'stray'"),
])
def test_bridge_rejects_bad_arguments(argv, needle):
    r = run(exe("can_bridge"), *argv)
    assert r.returncode == 2
    assert needle in r.stderr


@pytest.mark.parametrize("iface", [["--iface", "nosuchcan0"], ["--iface=nosuchcan0"]])
def test_bridge_without_the_interface_says_so(iface):
    r = run(exe("can_bridge"), *iface)
    assert r.returncode == 1
    assert "no CAN support" in r.stderr or "no such CAN interface" in r.stderr


@pytest.mark.parametrize("argv", [["--iface", "nosuchcan0"], ["--iface=nosuchcan0", "--node=3"]])
def test_controller_takes_the_bridges_can_flags(argv):
    """pour_controller --iface IFACE [--node N] is its --io can:IFACE[,node=N]."""
    r = run(exe("pour_controller"), *argv)
    assert r.returncode == 1
    assert "no CAN support" in r.stderr or "no such CAN interface" in r.stderr


def test_bridge_help_names_the_channels():
    r = run(exe("can_bridge"), "--help")
    assert r.returncode == 0 and "POUR_SENSORS" in r.stdout and "POUR_TORQUE" in r.stdout
