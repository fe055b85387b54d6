# SPDX-License-Identifier: MIT
"""LCM channel names and the default URL, the Python twin of lcmtypes/include/pour_lcm/channels.h."""

SENSORS = "POUR_SENSORS"
"""Raw sensor sample (encoder count, two scales), host_sim or a rig -> controller, every 1 ms tick
(pour.sensor_sample_t). The only plant input the controller has."""
TRUTH = "POUR_TRUTH"
"""Ground truth of the simulated plant, host_sim -> bench tools only, every tick (pour.plant_truth_t);
no controller subscribes to it."""
TORQUE = "POUR_TORQUE"
"""Torque answering one sensor sample, controller -> host_sim (pour.torque_t)."""
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

ALL = (SENSORS, TRUTH, TORQUE, STATUS, PARTICLES, COMMAND)
