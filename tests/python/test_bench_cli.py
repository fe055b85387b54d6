# SPDX-License-Identifier: MIT
"""pour-bench's bad input on any kernel (the bus itself is tested in the user-mode Linux guest,
tests/can/guest/test_bench.py): a bad command line is 2, a bus that cannot open or a command this firmware
lacks is 1, each with a message that names the problem."""
from __future__ import annotations

import subprocess
import sys

import pytest


def bench(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pour.bench.cli", *argv], capture_output=True, text=True,
                          timeout=60)


@pytest.mark.parametrize("argv, needle", [
    (["--node", "64", "info"], "node id 64 outside 0..63"),
    (["--node", "x", "info"], "'x' is not a decimal integer"),
    (["--timeout", "0", "info"], "not a number of seconds"),
    (["--expect-hash", "0xnothex", "clear"], "not a 32-bit policy hash"),
    (["config", "set", "omega_max", "1.5"], "'1.5' is not a decimal integer"),
    (["config", "set", "omega_max"], "the following arguments are required: value"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
    ([], "the following arguments are required: COMMAND"),
])
def test_bad_command_lines_are_status_2(argv, needle):
    r = bench(*argv)
    assert r.returncode == 2 and needle in r.stderr, r.stderr


def test_a_bad_weights_file_is_status_2(tmp_path):
    bad = tmp_path / "weights.h"
    bad.write_text("not a header\n")
    r = bench("--iface", "nosuchcan0", "--weights", str(bad), "clear")
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith(f"pour-bench: error: --weights {bad}: "), r.stderr
    r = bench("--iface", "nosuchcan0", "reset")
    assert r.returncode == 2 and "'reset' can move the axis: give the policy you expect" in r.stderr, r.stderr


def test_calibrate_is_not_available_over_this_firmware():
    r = bench("calibrate")
    assert r.returncode == 1
    assert "calibrate is not available over this firmware" in r.stderr


def test_a_bus_that_cannot_open_says_which():
    r = bench("--iface", "nosuchcan0", "scan")
    assert r.returncode == 1
    assert "pour-bench: error: cannot open CAN bus socketcan:nosuchcan0" in r.stderr, r.stderr


def test_config_list_names_the_dbc_parameters_without_a_bus():
    r = bench("--iface", "nosuchcan0", "config", "list")
    assert r.returncode == 0, r.stderr
    assert "  4 omega_max" in r.stdout and " 22 scale_target_tare" in r.stdout, r.stdout
