/* SPDX-License-Identifier: MIT */
/* Register tables. Every driver lists the STM32G431 registers and fields it touches once, as X-macros:
 *   POUR_<X>_PERIPHS(P)  P(instance, block, base address)
 *   POUR_<X>_REGS(R)     R(block, register, byte offset)
 *   POUR_<X>_FIELDS(F)   F(block, register, field, first bit, width in bits)
 * Names are RM0440's, as ST's SVD spells them (the stm32g4 crate's accessors, upper case), so that
 * tests/board/check_registers.py compares each entry with ST's description of the chip. From a table the
 * driver gets, through the macros below, POUR_<block>_<register> (a word index from the instance base),
 * POUR_<instance>_BASE, and each field's _POS and _WIDTH; nothing is typed in twice. */
#ifndef POUR_REGS_H
#define POUR_REGS_H

#include <stdint.h>

#define POUR_REGS_BASE_ENUM(inst, block, base) POUR_##inst##_BASE = (base),
#define POUR_REGS_INDEX_ENUM(block, reg, offset) POUR_##block##_##reg = (offset) / 4,
#define POUR_REGS_FIELD_ENUM(block, reg, field, pos, width)                                                      \
  POUR_##block##_##reg##_##field##_POS = (pos), POUR_##block##_##reg##_##field##_WIDTH = (width),

/* Declares the enums of one driver's table X (POUR_X_PERIPHS, POUR_X_REGS, POUR_X_FIELDS). */
#define POUR_REGS_DECLARE(X)                                                                                    \
  enum { POUR_##X##_PERIPHS(POUR_REGS_BASE_ENUM) };                                                             \
  enum { POUR_##X##_REGS(POUR_REGS_INDEX_ENUM) };                                                               \
  enum { POUR_##X##_FIELDS(POUR_REGS_FIELD_ENUM) }

/* A field's mask in its register, a value placed in it (truncated to the field), a value read from it. */
#define POUR_MSK(block, reg, field)                                                                             \
  ((0xFFFFFFFFu >> (32u - (uint32_t)POUR_##block##_##reg##_##field##_WIDTH)) << POUR_##block##_##reg##_##field##_POS)
#define POUR_VAL(block, reg, field, v)                                                                          \
  ((((uint32_t)(v)) << POUR_##block##_##reg##_##field##_POS) & POUR_MSK(block, reg, field))
#define POUR_GET(block, reg, field, word) (((uint32_t)(word) & POUR_MSK(block, reg, field)) >> POUR_##block##_##reg##_##field##_POS)

/* Polls *reg until (*reg & mask) == want, at most polls times: 0, or -1 if the hardware never got there
 * (every wait of the port is bounded: a flag that never comes is an error, not a hang). */
static inline int pour_regs_wait(const volatile uint32_t *reg, uint32_t mask, uint32_t want, uint32_t polls) {
  for (uint32_t i = 0; i < polls; ++i) {
    if ((*reg & mask) == want) {
      return 0;
    }
  }
  return -1;
}

/* The Cortex-M4's SysTick (ARMv7-M architecture, not in ST's description of the chip): its base and word
 * indices, and the control bits the port uses. */
#define POUR_SYSTICK_BASE 0xE000E010u
enum { POUR_SYST_CSR = 0, POUR_SYST_RVR = 1, POUR_SYST_CVR = 2 };
#define POUR_SYST_CSR_ENABLE 0x1u
#define POUR_SYST_CSR_TICKINT 0x2u
#define POUR_SYST_CSR_CLKSOURCE_CORE 0x4u
#define POUR_SYST_MAX 0xFFFFFFu /* the 24-bit down-counter's reload */

/* An instance's registers as a word array (only where the driver runs on the chip, never in host tests). */
#define POUR_PERIPH(inst) ((volatile uint32_t *)(uintptr_t)POUR_##inst##_BASE)

#endif /* POUR_REGS_H */
