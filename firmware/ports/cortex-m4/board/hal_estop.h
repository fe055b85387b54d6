/* SPDX-License-Identifier: MIT */
/* hal_estop: the hardwired e-stop input, active low (a broken wire reads as asserted), read every tick in
 * addition to the CAN Estop frame. */
#ifndef POUR_HAL_ESTOP_H
#define POUR_HAL_ESTOP_H

#include <stdbool.h>

/* Configures the input (pull-down: an open circuit or a broken wire asserts the e-stop). */
void pour_hal_estop_init(void);

/* true while the e-stop is asserted (the line is low). */
bool pour_hal_estop_asserted(void);

#endif /* POUR_HAL_ESTOP_H */
