/* SPDX-License-Identifier: MIT */
/* The core clock: the STM32G431 at 170 MHz through the PLL, from the board's crystal (HSE) or, if the
 * crystal does not start, from the internal HSI16, which is then reported (RM0440 §6, §7). */
#ifndef POUR_CLOCK_H
#define POUR_CLOCK_H

#include <stdint.h>

#include "pour/fixed.h"

/* Where the PLL's input came from. */
typedef enum {
  POUR_CLOCK_HSI16 = 0, /* the crystal did not start (or the PLL never locked): internal 16 MHz RC, ±1 % */
  POUR_CLOCK_HSE = 1    /* the board's crystal */
} pour_clock_source_t;

/* The registers the clock set-up writes (the chip's, or a register file in a host test). */
typedef struct {
  volatile uint32_t *rcc, *pwr, *flash;
} pour_clock_hw_t;

typedef struct {
  uint32_t hse_hz;      /* the board's crystal [Hz]: a multiple of 4 MHz, 4 .. 48 MHz */
  uint32_t ready_polls; /* bound of every ready-flag wait, > 0: a flag that never comes is an error */
} pour_clock_config_t;

/* B-G431B-ESC1: a 24 MHz crystal (docs/bringup.md says how sure that is and how the bench checks it). */
pour_clock_config_t pour_clock_default_config(void);

/* PLL to 170 MHz from the crystal, HSI16 if the crystal is not ready in time; *core_clock_hz gets the clock
 * the core runs at [Hz] (also APB1, FDCAN's kernel clock), *source where it came from. POUR_EINVAL for a
 * bad config or a PLL that does not lock (the core then stays on HSI16 at 16 MHz, as *core_clock_hz says). */
pour_status_t pour_clock_setup(const pour_clock_hw_t *hw, const pour_clock_config_t *config, uint32_t *core_clock_hz,
                               pour_clock_source_t *source);

/* The board's set-up (board_stm32g431.c: the chip's registers, the default config). */
pour_status_t pour_clock_init(uint32_t *core_clock_hz);

/* The source pour_clock_init chose (for the heartbeat's drive telemetry and the LED). */
pour_clock_source_t pour_clock_source(void);

#endif /* POUR_CLOCK_H */
