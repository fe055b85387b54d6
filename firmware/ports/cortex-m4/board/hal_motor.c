/* SPDX-License-Identifier: MIT */
/* The torque command as the 1 kHz tick leaves it: board_drive hands it to the current loop as its
 * reference (pour_drive_tick), derated by the board's protection. */
#include "hal_motor.h"

static volatile q15_t command;

void pour_hal_motor_init(void) { command = 0; }

void pour_hal_motor_set_torque(q15_t torque) { command = torque; }

q15_t pour_hal_motor_torque(void) { return command; }
