/* SPDX-License-Identifier: MIT */
/* hal_motor: the torque command to the motor driver. One implementation per port: the Cortex-M4 keeps it for
 * the drive (hal_motor.c); the Linux process sends it in its answer and keeps the line for its summary. */
#ifndef POUR_HAL_MOTOR_H
#define POUR_HAL_MOTOR_H

#include "pour/fixed.h"

/* Puts the driver in a known state at zero torque. */
void pour_hal_motor_init(void);

/* Commands torque as a fraction of tau_max, Q15. */
void pour_hal_motor_set_torque(q15_t torque);

/* The last command (for status reports). */
q15_t pour_hal_motor_torque(void);

#endif /* POUR_HAL_MOTOR_H */
