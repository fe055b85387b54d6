/* SPDX-License-Identifier: MIT */
/* What the Linux port's brake and power lines did (hal_brake.c, hal_power.c), for its exit summary. */
#ifndef POUR_LINUX_HAL_LINES_H
#define POUR_LINUX_HAL_LINES_H

/* Times the brake was engaged after having been released. */
long pour_hal_brake_engagements(void);

/* Times the power stage was cut after having been on. */
long pour_hal_power_cuts(void);

#endif /* POUR_LINUX_HAL_LINES_H */
