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

#ifndef POUR_SEMIHOSTED
/* STM32G431 device interrupts (RM0440): IRQ 0..101 follow the 16 core entries. A driver provides a
 * handler by defining its name (the FDCAN driver: FDCAN1_IT0_IRQHandler, FDCAN1_IT1_IRQHandler); every
 * other interrupt stops in Default_Handler. */
void FDCAN1_IT0_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
void FDCAN1_IT1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
#define D1 Default_Handler
#define D4 D1, D1, D1, D1
#define D20 D4, D4, D4, D4, D4
#define POUR_DEVICE_VECTORS                                                                    \
  D20, D1,                           /* IRQ 0..20 */                                           \
      FDCAN1_IT0_IRQHandler,         /* IRQ 21 */                                              \
      FDCAN1_IT1_IRQHandler,         /* IRQ 22 */                                              \
      D20, D20, D20, D4, D4, D4, D1, D1, D1 /* IRQ 23..101 */
#define POUR_N_DEVICE_VECTORS 102
#else
/* QEMU mps2-an386 images (tests, benchmark) use no device interrupt. */
#define POUR_DEVICE_VECTORS
#define POUR_N_DEVICE_VECTORS 0
#endif

/* Cortex-M4 core exceptions, then the device's. Unused entries stop in Default_Handler. */
typedef void (*pour_vector_t)(void);
__attribute__((section(".isr_vector"), used)) static const pour_vector_t vectors[16 + POUR_N_DEVICE_VECTORS] = {
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
    POUR_DEVICE_VECTORS
};
