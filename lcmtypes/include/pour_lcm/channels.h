/* SPDX-License-Identifier: MIT */
/* LCM channel names and the default URL: the one place C and C++ code take them from
 * (tools/pour/lcm/channels.py is the Python twin; a test checks that both agree). */
#ifndef POUR_LCM_CHANNELS_H
#define POUR_LCM_CHANNELS_H

/* Raw sensor sample (encoder count, two scales), host_sim or a rig -> controller, every 1 ms tick
 * (pour_sensor_sample_t). The only plant input the controller has. */
#define POUR_LCM_CHANNEL_SENSORS "POUR_SENSORS"
/* Ground truth of the simulated plant, host_sim -> bench tools only, every tick (pour_plant_truth_t);
 * no controller subscribes to it. */
#define POUR_LCM_CHANNEL_TRUTH "POUR_TRUTH"
/* Torque answering one sensor sample, controller -> host_sim (pour_torque_t). */
#define POUR_LCM_CHANNEL_TORQUE "POUR_TORQUE"
/* Controller health at about 10 Hz (pour_controller_status_t). */
#define POUR_LCM_CHANNEL_STATUS "POUR_STATUS"
/* Circle positions at a viewing rate (pour_particles_t). */
#define POUR_LCM_CHANNEL_PARTICLES "POUR_PARTICLES"
/* Operator commands: e-stop, clear faults (pour_command_t). */
#define POUR_LCM_CHANNEL_COMMAND "POUR_COMMAND"

/* Multicast on the local machine only (ttl=0); works on loopback as is. */
#define POUR_LCM_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"

/* Status period of the controller [ms] and the particle snapshot period of host_sim [ms]. */
#define POUR_LCM_STATUS_PERIOD_MS 100
#define POUR_LCM_PARTICLES_PERIOD_MS 33

#endif /* POUR_LCM_CHANNELS_H */
