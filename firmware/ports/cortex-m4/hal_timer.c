/* SPDX-License-Identifier: MIT */
#include "hal_timer.h"

/* SysTick is part of every Cortex-M4 core, so this one file serves the STM32G431 and QEMU alike. */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_CSR_ENABLE 0x1u
#define SYST_CSR_TICKINT 0x2u
#define SYST_CSR_CLKSOURCE_CORE 0x4u

static volatile uint32_t ticks;
static uint32_t ticks_seen;

void pour_hal_timer_init(uint32_t core_clock_hz) {
  SYST_CSR = 0u;
  SYST_RVR = core_clock_hz / 1000u - 1u;
  SYST_CVR = 0u;
  ticks = 0u;
  ticks_seen = 0u;
  SYST_CSR = SYST_CSR_ENABLE | SYST_CSR_TICKINT | SYST_CSR_CLKSOURCE_CORE;
}

void pour_hal_timer_isr(void) { ticks = ticks + 1u; }

uint32_t pour_hal_timer_wait_tick(void) {
  for (;;) {
    /* With PRIMASK set, a SysTick that fires after the check stays pending and WFI returns at once;
     * checking and then sleeping with interrupts on could sleep through it (a whole period lost). */
    __asm volatile("cpsid i" ::: "memory");
    if (ticks != ticks_seen) {
      __asm volatile("cpsie i" ::: "memory");
      break;
    }
    __asm volatile("wfi");
    __asm volatile("cpsie i" ::: "memory");
  }
  const uint32_t now = ticks;
  const uint32_t missed = now - ticks_seen - 1u;
  ticks_seen = now;
  return missed;
}

uint32_t pour_hal_timer_ticks(void) { return ticks; }
