/* SPDX-License-Identifier: MIT */
/* The chip's side of the clock set-up, for a thread that plays it against register files (RM0440 RCC, LPTIM;
 * ARMv7-M SysTick): CFGR.SWS follows CFGR.SW, LPTIM1 reports ARROK once enabled and counts HSI16 through its
 * prescaler once started, SysTick counts down at HCLK (the crystal / 2 while the crystal is timed). Both
 * counters follow one emulated time, the host's monotonic clock slowed 10 times and advanced at most 1 us per
 * step: the ratio of their counts is that of the two oscillators, and a thread descheduled on a loaded
 * machine stalls the chip's time rather than making it jump. Host only (clock_gettime). */
#ifndef POUR_TESTS_CLOCK_CHIP_H
#define POUR_TESTS_CLOCK_CHIP_H

#include <stdint.h>
#include <time.h>

#include "stm32g431_regs.h"

#define CLOCK_CHIP_SLOWDOWN 10u
#define CLOCK_CHIP_STEP_MAX_NS 1000u

typedef struct {
  volatile uint32_t *rcc, *lptim, *systick;
  uint64_t crystal_mhz_x10;                          /* the emulated crystal [0.1 MHz] */
  uint64_t last, now, lptim_start, systick_start;    /* the host's time, the chip's times [ns] */
} clock_chip_t;

static inline uint64_t clock_chip_host_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static inline void clock_chip_start(clock_chip_t *c) {
  c->last = clock_chip_host_ns();
  c->now = c->lptim_start = c->systick_start = 0u;
}

/* One step of the chip: call it in a loop from the thread that plays the chip. */
static inline void clock_chip_step(clock_chip_t *c) {
  volatile uint32_t *const rcc = c->rcc, *const lptim = c->lptim, *const systick = c->systick;
  const uint64_t host = clock_chip_host_ns(), step = (host - c->last) / CLOCK_CHIP_SLOWDOWN;
  c->last = host;
  c->now += step < CLOCK_CHIP_STEP_MAX_NS ? step : CLOCK_CHIP_STEP_MAX_NS;
  const uint32_t cfgr = rcc[POUR_RCC_CFGR];
  const uint32_t sw = POUR_GET(RCC, CFGR, SW, cfgr);
  if (POUR_GET(RCC, CFGR, SWS, cfgr) != sw) { /* written only on a switch, while the code only polls */
    rcc[POUR_RCC_CFGR] = (cfgr & ~POUR_MSK(RCC, CFGR, SWS)) | POUR_VAL(RCC, CFGR, SWS, sw);
  }
  const uint32_t cr = lptim[POUR_LPTIM_CR];
  if ((cr & POUR_MSK(LPTIM, CR, ENABLE)) != 0u && lptim[POUR_LPTIM_ARR] != 0u) {
    lptim[POUR_LPTIM_ISR] |= POUR_MSK(LPTIM, ISR, ARROK);
  }
  if ((cr & POUR_MSK(LPTIM, CR, CNTSTRT)) == 0u) {
    c->lptim_start = 0u;
  } else {
    c->lptim_start = c->lptim_start != 0u ? c->lptim_start : c->now;
    const uint64_t presc = 1u << POUR_GET(LPTIM, CFGR, PRESC, lptim[POUR_LPTIM_CFGR]);
    lptim[POUR_LPTIM_CNT] = (uint32_t)((c->now - c->lptim_start) * 16u / 1000u / presc) & 0xFFFFu; /* HSI16 */
  }
  if ((systick[POUR_SYST_CSR] & POUR_SYST_CSR_ENABLE) == 0u || sw != 2u) {
    c->systick_start = 0u;
  } else {
    c->systick_start = c->systick_start != 0u ? c->systick_start : c->now;
    const uint64_t ticks = (c->now - c->systick_start) * c->crystal_mhz_x10 / 20000u; /* crystal / 2 */
    systick[POUR_SYST_CVR] = (uint32_t)(0u - ticks) & POUR_SYST_MAX;
  }
}

#endif /* POUR_TESTS_CLOCK_CHIP_H */
