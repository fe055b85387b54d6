/* SPDX-License-Identifier: MIT */
/* Counting instructions on QEMU mps2-an386 under -icount shift=0 (one instruction per virtual ns): SysTick
 * free-running from the core clock, and a loop of known length that converts its ticks to instructions.
 * For the benchmark images only. */
#ifndef POUR_BENCH_ICOUNT_H
#define POUR_BENCH_ICOUNT_H

#include <stdint.h>

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define CAL_ITERATIONS 200000u

static uint32_t now(void) { return SYST_CVR; } /* counts down */

static uint32_t elapsed(uint32_t start, uint32_t end) { return (start - end) & 0x00FFFFFFu; }

/* 3 instructions per iteration (subs, nop, bne), in assembly so the count does not depend on flags. */
static void spin(uint32_t n) {
  __asm volatile("1: subs %0, %0, #1\n nop\n bne 1b\n" : "+r"(n) : : "cc");
}

/* Starts SysTick (24 bits, core clock, no interrupt) and returns instructions per 1000 ticks. */
static uint32_t icount_start(void) {
  SYST_CSR = 0u;
  SYST_RVR = 0x00FFFFFFu;
  SYST_CVR = 0u;
  SYST_CSR = 0x5u;
  const uint32_t t0 = now();
  spin(CAL_ITERATIONS);
  return (uint32_t)((3000ull * CAL_ITERATIONS) / elapsed(t0, now()));
}

#endif /* POUR_BENCH_ICOUNT_H */
