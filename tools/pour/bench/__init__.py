# SPDX-License-Identifier: MIT
"""The bench over CAN: a Python API on python-can and cantools (node: scan, state, commands, parameters,
telemetry and logs) and the pour-bench CLI (cli)."""
