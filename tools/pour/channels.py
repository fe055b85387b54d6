# SPDX-License-Identifier: MIT
"""LCM channel names and the default URL, the Python twin of lcmtypes/include/pour_lcm/channels.h."""

STATE = "POUR_STATE"
"""Plant state, host_sim -> controller, every 1 ms tick (pour.plant_state_t)."""
TORQUE = "POUR_TORQUE"
"""Torque answering one state, controller -> host_sim (pour.torque_t)."""
STATUS = "POUR_STATUS"
"""Controller health at about 10 Hz (pour.controller_status_t)."""
PARTICLES = "POUR_PARTICLES"
"""Circle positions at a viewing rate (pour.particles_t)."""
COMMAND = "POUR_COMMAND"
"""Operator commands: e-stop, clear faults (pour.command_t)."""

DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=0"
"""Multicast on the local machine only (ttl=0); works on loopback as is."""

STATUS_PERIOD_MS = 100
PARTICLES_PERIOD_MS = 33

ALL = (STATE, TORQUE, STATUS, PARTICLES, COMMAND)
