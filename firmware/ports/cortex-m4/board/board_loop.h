/* SPDX-License-Identifier: MIT */
/* One 1 kHz tick of the board around the core, port-neutral over the hal_* calls: the hardwired e-stop line
 * around the bus's frames into the CAN node; an ExperimentStart to the core before the step, answered after
 * it; the drive's tick (board_drive: the protection, the core's step, the outputs) with the calibration flow
 * (calibration_flow) after the step; the LED; the drive's telemetry and the node's frames on the bus. */
#ifndef POUR_BOARD_LOOP_H
#define POUR_BOARD_LOOP_H

#include <stdint.h>

#include "pour/can_node.h"
#include "pour/control.h"

/* The calibration flow on what hal_calibration loaded at boot, run by the drive's tick from now on. Call
 * after pour_board_drive_init and with the node ready. */
void pour_board_loop_init(pour_can_node_t *node);

/* One tick; overruns: the ticks the loop has missed since boot (the heartbeat carries them). */
void pour_board_loop_tick(pour_control_t *ctl, pour_can_node_t *node, uint32_t overruns);

/* The frames of one tick onto the bus (a full mailbox drops them: the next tick says it again). */
void pour_board_transmit(const pour_can_frame_t *tx, uint8_t n);

#endif /* POUR_BOARD_LOOP_H */
