# SPDX-License-Identifier: MIT
"""System identification: the controller's own experiment's candump log -> a rig file the simulator reads
(docs/bench.md, "System identification")."""
