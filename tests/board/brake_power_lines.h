/* SPDX-License-Identifier: MIT */
/* hal_brake and hal_power answered by two plain variables, for the host benches that stand in for the board
 * (each test file gets its own copy): brake_line true = engaged (spring-applied: so from power-up until set
 * otherwise), power_line true = the power stage on. */
#ifndef POUR_BRAKE_POWER_LINES_H
#define POUR_BRAKE_POWER_LINES_H

#include <stdbool.h>

#include "hal_brake.h"
#include "hal_power.h"

static bool brake_line = true, power_line;

void pour_hal_brake_init(void) { brake_line = true; }
void pour_hal_brake_set(bool engage) { brake_line = engage; }
bool pour_hal_brake_engaged(void) { return brake_line; }
void pour_hal_power_init(void) { power_line = false; }
void pour_hal_power_set(bool on) { power_line = on; }
bool pour_hal_power_on(void) { return power_line; }

#endif /* POUR_BRAKE_POWER_LINES_H */
