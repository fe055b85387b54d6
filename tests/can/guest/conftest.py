# SPDX-License-Identifier: MIT
"""These tests run inside the user-mode Linux guest that tests/can/uml_run.py boots (ctest label can)."""
from pathlib import Path

import pytest


def pytest_configure(config: pytest.Config) -> None:
    if not Path("/sys/class/net/vcan0").exists():
        raise pytest.UsageError("tests/can/guest needs vcan0: run them through tests/can/uml_run.py "
                                "(ctest -L can does), this kernel has no SocketCAN")
