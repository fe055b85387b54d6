/* SPDX-License-Identifier: MIT */
/* hal_watchdog: the independent watchdog (IWDG, its own 32 kHz oscillator): fed once per healthy tick,
 * it resets the MCU (brake engaged, power off: the reset state of both lines) if the loop stops. */
#ifndef POUR_HAL_WATCHDOG_H
#define POUR_HAL_WATCHDOG_H

#include <stdint.h>

#include "pour/board_facts.h"

/* The loop's timeout: ten missed ticks, the loop is gone (brake engaged meanwhile) [ms]. */
#define POUR_WATCHDOG_TIMEOUT_MS 10u
/* While a flash page is erased and programmed (the single-bank G431 stalls every fetch meanwhile, the loop
 * included): the longest erase, the program and read-back, and margin [ms]. */
#define POUR_WATCHDOG_FLASH_MS (((uint32_t)POUR_BOARD_FLASH_PAGE_ERASE_MAX_US + 999u) / 1000u + 10u)

/* Starts it with a timeout of at least timeout_ms [ms] (1 .. 480); once started it cannot be stopped. */
void pour_hal_watchdog_start(uint32_t timeout_ms);

/* A new timeout of at least timeout_ms [ms] (1 .. 480), from now. */
void pour_hal_watchdog_set_timeout(uint32_t timeout_ms);

/* Restarts the timeout. */
void pour_hal_watchdog_feed(void);

#endif /* POUR_HAL_WATCHDOG_H */
