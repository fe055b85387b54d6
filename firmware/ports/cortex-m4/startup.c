/* SPDX-License-Identifier: MIT */
/* Vector table and reset for Cortex-M4 (STM32G431 and QEMU mps2-an386): copy .data from flash, zero
 * .bss, then main. Semihosted images (tests, benchmark; POUR_SEMIHOSTED) hand over to newlib's rdimon
 * crt0 (_start) instead, which also opens the semihosting stdio and passes main's status to exit(). */
#include <stdint.h>

#include "hal_timer.h"

extern uint32_t __data_load__, __data_start__, __data_end__, __bss_start__, __bss_end__, __StackTop;
extern int main(void);
void Reset_Handler(void);
void Default_Handler(void);
#ifdef POUR_SEMIHOSTED
extern void _start(void);
#endif

void Default_Handler(void) {
  for (;;) {
  }
}

void Reset_Handler(void) {
  uint32_t *src = &__data_load__;
  for (uint32_t *dst = &__data_start__; dst < &__data_end__;) {
    *dst++ = *src++;
  }
  for (uint32_t *dst = &__bss_start__; dst < &__bss_end__;) {
    *dst++ = 0u;
  }
#ifdef POUR_SEMIHOSTED
  _start();
#else
  (void)main();
#endif
  for (;;) {
  }
}

/* Cortex-M4 core exceptions; device interrupts (FDCAN, timers) follow from entry 16 when a driver needs
 * them. Unused entries stop in Default_Handler. */
typedef void (*pour_vector_t)(void);
__attribute__((section(".isr_vector"), used)) static const pour_vector_t vectors[16] = {
    (pour_vector_t)(uintptr_t)&__StackTop,
    Reset_Handler,
    Default_Handler, /* NMI */
    Default_Handler, /* HardFault */
    Default_Handler, /* MemManage */
    Default_Handler, /* BusFault */
    Default_Handler, /* UsageFault */
    0, 0, 0, 0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMonitor */
    0,
    Default_Handler, /* PendSV */
    pour_hal_timer_isr, /* SysTick */
};
