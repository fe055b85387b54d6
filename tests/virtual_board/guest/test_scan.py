# SPDX-License-Identifier: MIT
"""Inside the user-mode Linux guest with vcan0 (tests/can/uml_run.py): the virtual board runs the flashed
image on vcan0, and pour-bench scan finds its node by its heartbeat, as it would a real board."""
from __future__ import annotations

import os
import subprocess
import sys
import time


def test_pour_bench_scan_finds_the_virtual_board():
    board = subprocess.Popen([os.environ["POUR_VB"], "--elf", os.environ["POUR_ELF"],
                              "--channel", "vcan0", "--seconds", "120"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(2.0)  # boot and the first heartbeat (11.5 ms emulated), at the guest's pace
        assert board.poll() is None, board.communicate()
        r = subprocess.run([sys.executable, "-m", "pour.bench.cli", "--channel", "vcan0", "--timeout", "5", "scan"],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, (r.stdout, r.stderr)
        # One node, 0 (the image's default id), with its Identity frame (policy, firmware): the heartbeat and
        # identity the image sends, decoded by pour-bench as a real board's.
        lines = [line for line in r.stdout.splitlines() if line.startswith("node ")]
        assert len(lines) == 1 and lines[0].startswith("node 0: mode ") and "policy 0x" in lines[0], r.stdout
    finally:
        board.terminate()
        board.wait(timeout=10)
