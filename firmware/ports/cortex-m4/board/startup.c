/* SPDX-License-Identifier: MIT */
/* Vector table and reset for Cortex-M4 (STM32G431 and QEMU mps2-an386): copy .data from flash, zero
 * .bss, then main. Semihosted images (tests, benchmark; POUR_SEMIHOSTED) hand over to newlib's rdimon
 * crt0 (_start) instead, which also opens the semihosting stdio and passes main's status to exit(). */
#include <stdint.h>

#include "hal_timer.h"
#include "safe_outputs.h"
#ifndef POUR_SEMIHOSTED
#include "adc_inj.h"
#include "board_drive.h"
#endif

extern uint32_t __data_load__, __data_start__, __data_end__, __bss_start__, __bss_end__, __StackTop;
extern int main(void);
void Reset_Handler(void);
void Default_Handler(void);
__attribute__((weak)) void pour_safe_outputs(void) {}
#ifdef POUR_SEMIHOSTED
extern void _start(void);
#endif

/* Every fault and unexpected interrupt: the outputs to their safe levels first, then stop. The loop no
 * longer feeds the independent watchdog, which resets the MCU; it restarts with the brake engaged. */
void Fault_Handler(void) {
  pour_safe_outputs();
  for (;;) {
  }
}

void Default_Handler(void) { Fault_Handler(); }

/* The NMI: a fault unless the board says otherwise (board_stm32g431.c: a flash ECC error on a data page). */
__attribute__((weak)) void NMI_Handler(void) { Fault_Handler(); }

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
/* STM32G431 device interrupts (RM0440): IRQ 0..101 follow the 16 core entries. One is enabled: ADC1_2
 * (POUR_ADC_IRQ), the end of each PWM period's conversions, runs the current loop. The 1 kHz loop polls
 * every other peripheral: any other entry stops in Default_Handler (safe outputs first). */
#define D1 Default_Handler
#define D3 D1, D1, D1
#define D5 D1, D1, D1, D1, D1
#define D20 D5, D5, D5, D5
#define POUR_DEVICE_VECTORS D5, D5, D5, D3, pour_board_drive_isr, D20, D20, D20, D20, D3 /* IRQ 0..101 */
#define POUR_N_DEVICE_VECTORS 102
_Static_assert(POUR_ADC_IRQ == 18u, "the current loop's entry is the 19th device vector (5 + 5 + 5 + 3 before it)");
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
    NMI_Handler,   /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0, 0, 0, 0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMonitor */
    0,
    Default_Handler, /* PendSV */
    pour_hal_timer_isr, /* SysTick */
    POUR_DEVICE_VECTORS
};
