/* SPDX-License-Identifier: MIT */
/* A drive of the controller's own for a bench without a board (pour_controller_sim --io can:IFACE,drive=sim): the
 * firmware's drive (pour::motor) and the board's calibration flow (calibration_flow.c, its block stored by
 * calibration_store.c in a flash page held in memory) run against host_sim's motor model, the default motor
 * with the empty bucket on its bearing. It serves CalibrationStart only: the torque the core commands still
 * goes to the bus (the plant, host_sim through can_bridge, has its own drive), and RUN does not wait for it.
 * It has no sensors of its own: the board's interlock (pour_calibration_flow_sense: a recent sample, upright,
 * empty) is not applied, a start is refused only in RUN and ESTOP. */
#ifndef POUR_LINUX_SIM_DRIVE_H
#define POUR_LINUX_SIM_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/can_node.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Builds the drive (its start-up current offsets run here) with nothing stored; tells node so. 0, or -1
 * with a message on stderr. */
int pour_sim_drive_open(pour_can_node_t *node);

/* One 1 ms tick after the core's step (mode: its pour_mode_t): the calibration flow, then while the sequence
 * runs the drive's 20 PWM periods against the model. Returns true while it runs. */
bool pour_sim_drive_tick(pour_can_node_t *node, uint8_t mode);

#ifdef __cplusplus
}
#endif

#endif /* POUR_LINUX_SIM_DRIVE_H */
