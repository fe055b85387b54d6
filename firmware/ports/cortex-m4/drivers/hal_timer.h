/* SPDX-License-Identifier: MIT */
/* hal_timer: the 1 kHz control tick (SysTick) and a free-running count for measurements. */
#ifndef POUR_HAL_TIMER_H
#define POUR_HAL_TIMER_H

#include <stdint.h>

/* Starts SysTick at 1 kHz from a core clock of core_clock_hz [Hz] (>= 1000, reload fits 24 bits). */
void pour_hal_timer_init(uint32_t core_clock_hz);

/* Sleeps (WFI) until the next 1 ms tick; returns the number of ticks missed since the last call.
 * Interrupts are masked between the check and the WFI, so a tick that lands in between still wakes it. */
uint32_t pour_hal_timer_wait_tick(void);

/* Ticks since init. */
uint32_t pour_hal_timer_ticks(void);

/* SysTick exception handler (in the vector table). */
void pour_hal_timer_isr(void);

#endif /* POUR_HAL_TIMER_H */
