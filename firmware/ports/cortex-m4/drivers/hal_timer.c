/* SPDX-License-Identifier: MIT */
#include "hal_timer.h"

#include "regs.h"

/* SysTick is part of every Cortex-M4 core, so this one file serves the STM32G431 and QEMU alike. */
#define SYST ((volatile uint32_t *)(uintptr_t)POUR_SYSTICK_BASE)

static volatile uint32_t ticks;
static uint32_t ticks_seen;

void pour_hal_timer_init(uint32_t core_clock_hz) {
  SYST[POUR_SYST_CSR] = 0u;
  SYST[POUR_SYST_RVR] = core_clock_hz / 1000u - 1u;
  SYST[POUR_SYST_CVR] = 0u;
  ticks = 0u;
  ticks_seen = 0u;
  SYST[POUR_SYST_CSR] = POUR_SYST_CSR_ENABLE | POUR_SYST_CSR_TICKINT | POUR_SYST_CSR_CLKSOURCE_CORE;
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
