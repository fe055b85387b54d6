/* SPDX-License-Identifier: MIT */
/* hal_power: the motor power stage's enable. Fail-safe: enabled only while driven. One implementation per
 * port (Cortex-M4: a pin; Linux: the line kept for the process's summary). */
#ifndef POUR_HAL_POWER_H
#define POUR_HAL_POWER_H

#include <stdbool.h>

/* Configures the line with the power stage off. */
void pour_hal_power_init(void);

/* true: power stage on; false: off (the motor can give no torque). */
void pour_hal_power_set(bool on);

/* The line's current state (true: on). */
bool pour_hal_power_on(void);

#endif /* POUR_HAL_POWER_H */
