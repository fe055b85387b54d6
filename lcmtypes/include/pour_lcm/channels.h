/* SPDX-License-Identifier: MIT */
/* LCM channel names and the default URL: the one place C and C++ code take them from
 * (tools/pour/channels.py is the Python twin; a test checks that both agree). */
#ifndef POUR_LCM_CHANNELS_H
#define POUR_LCM_CHANNELS_H

/* Plant state, host_sim -> controller, every 1 ms tick (pour_plant_state_t). */
#define POUR_LCM_CHANNEL_STATE "POUR_STATE"
/* Torque answering one state, controller -> host_sim (pour_torque_t). */
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
