/* SPDX-License-Identifier: MIT */
/* The motor driver of this port is reached over CAN (the torque goes out in the answer frame), so the
 * local "driver" only keeps the latest command; a board with a PWM stage would write its timer here. */
#include "hal_motor.h"

static volatile q15_t command;

void pour_hal_motor_init(void) { command = 0; }

void pour_hal_motor_set_torque(q15_t torque) { command = torque; }

q15_t pour_hal_motor_torque(void) { return command; }
