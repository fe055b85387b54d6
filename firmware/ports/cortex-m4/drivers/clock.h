/* SPDX-License-Identifier: MIT */
/* The core clock: the STM32G431 at 170 MHz through the PLL, from the board's crystal (HSE) or, if the
 * crystal does not start or its frequency is not one the PLL can use, from the internal HSI16, which is then
 * reported (RM0440 §6, §7). The crystal's frequency is measured at boot against HSI16, not assumed: the
 * sources for the B-G431B-ESC1 disagree on it (docs/bringup.md). */
#ifndef POUR_CLOCK_H
#define POUR_CLOCK_H

#include <stdint.h>

#include "pour/fixed.h"

/* Where the PLL's input came from. */
typedef enum {
  POUR_CLOCK_HSI16 = 0, /* no usable crystal (it did not start, or timed at no multiple of 4 MHz up to 48 MHz),
                           or the PLL never locked: internal 16 MHz RC, ±1 % */
  POUR_CLOCK_HSE = 1    /* the board's crystal */
} pour_clock_source_t;

/* The registers the clock set-up writes (the chip's, or a register file in a host test): RCC, PWR, FLASH,
 * LPTIM1 and the core's SysTick (both only while the crystal is timed). */
typedef struct {
  volatile uint32_t *rcc, *pwr, *flash, *lptim, *systick;
} pour_clock_hw_t;

typedef struct {
  uint32_t ready_polls; /* bound of every wait, > 0: a flag that never comes, or a timing that never
                           ends, is an error, not a hang */
} pour_clock_config_t;

pour_clock_config_t pour_clock_default_config(void);

/* A measured crystal frequency [Hz] as the crystal it is: the nearest multiple of 4 MHz (the PLL's input)
 * from 4 to 48 MHz when within 3 % of it, else 0 (not a crystal this set-up can use). */
uint32_t pour_clock_crystal_hz(uint32_t measured_hz);

/* PLL to 170 MHz from the crystal, HSI16 if the crystal is not ready in time or times at no usable
 * frequency; *core_clock_hz gets the clock the core runs at [Hz] (also APB1, FDCAN's kernel clock), *source
 * where it came from, *crystal_hz the crystal the PLL runs from (0: none, the core is on HSI16). POUR_EINVAL
 * for a bad config or a PLL that does not lock (the core then stays on HSI16 at 16 MHz, as *core_clock_hz
 * says). */
pour_status_t pour_clock_setup(const pour_clock_hw_t *hw, const pour_clock_config_t *config, uint32_t *core_clock_hz,
                               pour_clock_source_t *source, uint32_t *crystal_hz);

/* The board's set-up (board_stm32g431.c: the chip's registers, the default config). */
pour_status_t pour_clock_init(uint32_t *core_clock_hz);

/* The crystal pour_clock_init found [Hz], 0 when the core runs from HSI16 (DriveTelemetry's Crystal). */
uint32_t pour_clock_crystal(void);

#endif /* POUR_CLOCK_H */
