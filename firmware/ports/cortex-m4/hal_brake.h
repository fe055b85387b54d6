/* SPDX-License-Identifier: MIT */
/* hal_brake: the axis's holding brake. Fail-safe: spring-applied, released only while driven, so a
 * reset, a brown-out or a crash leaves it engaged. */
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
