/* SPDX-License-Identifier: MIT */
/* hal_watchdog: the independent watchdog (IWDG, its own 32 kHz oscillator): fed once per healthy tick,
 * it resets the MCU (brake engaged, power off: the reset state of both lines) if the loop stops. */
#ifndef POUR_HAL_WATCHDOG_H
#define POUR_HAL_WATCHDOG_H

#include <stdint.h>

/* Starts it with a timeout of timeout_ms [ms] (1 .. 100); once started it cannot be stopped. */
void pour_hal_watchdog_start(uint32_t timeout_ms);

/* Restarts the timeout. */
void pour_hal_watchdog_feed(void);

#endif /* POUR_HAL_WATCHDOG_H */
