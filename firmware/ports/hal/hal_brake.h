/* SPDX-License-Identifier: MIT */
/* hal_brake: the axis's holding brake. Fail-safe: spring-applied, released only while driven, so a
 * reset, a brown-out or a crash leaves it engaged. One implementation per port: the Cortex-M4 drives a pin
 * (board_stm32g431.c); the Linux process has no brake of its own and keeps the line for its summary. */
#ifndef POUR_HAL_BRAKE_H
#define POUR_HAL_BRAKE_H

#include <stdbool.h>

/* Configures the line with the brake engaged. */
void pour_hal_brake_init(void);

/* true: engage (hold the bucket where it is); false: release. */
void pour_hal_brake_set(bool engage);

/* The line's current state (true: engaged). */
bool pour_hal_brake_engaged(void);

#endif /* POUR_HAL_BRAKE_H */
