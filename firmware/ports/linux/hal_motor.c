/* SPDX-License-Identifier: MIT */
/* hal_motor on Linux: the torque goes to the host in the answer (LCM, CAN); the line keeps the latest. */
#include "hal_motor.h"

static q15_t command;

void pour_hal_motor_init(void) { command = 0; }

void pour_hal_motor_set_torque(q15_t torque) { command = torque; }

q15_t pour_hal_motor_torque(void) { return command; }
