# SPDX-License-Identifier: MIT
"""tests/can/uml_run.py: boots a user-mode Linux guest with vcan0 and passes the command's exit status
back; a guest that does not boot, a hung command and bad arguments each fail with a clear message."""
from __future__ import annotations

import re
import subprocess
import sys

from conftest import SOURCE_DIR

UML_RUN = SOURCE_DIR / "tests" / "can" / "uml_run.py"


def uml_run(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(UML_RUN), *args], capture_output=True, text=True, timeout=timeout)


def test_guest_has_vcan0_and_returns_the_command_status(tmp_path):
    out = uml_run("--cwd", str(tmp_path), "--env", "GREETING=hi there", "--",
                  "sh", "-c", 'ip -details link show vcan0 && cansend vcan0 123#DEADBEEF && echo "$GREETING" '
                  '&& pwd && exit 7')
    assert out.returncode == 7, out.stderr
    assert "vcan0" in out.stdout and "link/can" in out.stdout
    assert "hi there" in out.stdout
    assert str(tmp_path) in out.stdout


def test_guest_has_af_can_for_python():
    code = ("import socket; s = socket.socket(socket.PF_CAN, socket.SOCK_RAW, socket.CAN_RAW); "
            "s.bind(('vcan0',)); print('bound')")
    out = uml_run("--", sys.executable, "-c", code)
    assert out.returncode == 0, out.stderr
    assert "bound" in out.stdout


def test_a_guest_that_does_not_boot_fails_with_a_message():
    out = uml_run("--kernel", "/bin/false", "--", "true")
    assert out.returncode == 3
    assert "did not boot" in out.stderr


def test_a_missing_kernel_names_the_set_up_step():
    out = uml_run("--kernel", "/nonexistent/linux", "--", "true")
    assert out.returncode == 3
    assert "/nonexistent/linux not found" in out.stderr and "scripts/lib/uml.sh" in out.stderr


def test_a_hung_command_times_out_and_the_guest_is_ended():
    out = uml_run("--timeout", "8", "--", "sleep", "60")
    assert out.returncode == 124
    assert "did not finish within 8 s" in out.stderr
    guest = re.search(r"\(guest (pour-uml-\S+) stopped\)", out.stderr).group(1)
    ps = subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True, check=True).stdout
    assert guest not in ps  # no process of that user-mode kernel is left


def test_bad_arguments_are_refused():
    assert uml_run().returncode == 2
    out = uml_run("--env", "NOEQUALS", "--", "true")
    assert out.returncode == 2 and "NAME=VALUE" in out.stderr
    out = uml_run("--timeout", "0", "--", "true")
    assert out.returncode == 2 and "--timeout" in out.stderr
