/* SPDX-License-Identifier: MIT */
/* OPAMP1..3, the phase shunts' amplifiers (B-G431B-ESC1: VINP0 on PA1, PA7, PB0 with the board's bias
 * network; outputs on their pins PA2, PA6, PB1 into the ADCs), high-speed mode. Either as programmable-gain
 * amplifiers (internal gain 2 .. 64) or with the board's own feedback network on VINM0 (PA3, PA5, PB2):
 * ST's motor-control profile of this board uses a gain of 9.14, which no internal gain gives, so the
 * board's default is the external network (pour_opamp_init with gain 0). */
#ifndef POUR_OPAMP_H
#define POUR_OPAMP_H

#include <stdint.h>

#include "pour/fixed.h"
#include "regs.h"

#define POUR_OPAMP_PERIPHS(P) P(OPAMP, OPAMP, 0x40010300)
#define POUR_OPAMP_REGS(R) R(OPAMP, OPAMP1_CSR, 0x00) R(OPAMP, OPAMP2_CSR, 0x04) R(OPAMP, OPAMP3_CSR, 0x08)
#define POUR_OPAMP_FIELDS(F)                                                                                   \
  F(OPAMP, OPAMP1_CSR, OPAEN, 0, 1)                                                                            \
  F(OPAMP, OPAMP1_CSR, VP_SEL, 2, 2)                                                                           \
  F(OPAMP, OPAMP1_CSR, VM_SEL, 5, 2)                                                                           \
  F(OPAMP, OPAMP1_CSR, OPAHSM, 7, 1)                                                                           \
  F(OPAMP, OPAMP1_CSR, OPAINTOEN, 8, 1)                                                                        \
  F(OPAMP, OPAMP1_CSR, PGA_GAIN, 14, 5)                                                                        \
  F(OPAMP, OPAMP1_CSR, LOCK, 31, 1)                                                                            \
  F(OPAMP, OPAMP2_CSR, PGA_GAIN, 14, 5)                                                                        \
  F(OPAMP, OPAMP3_CSR, PGA_GAIN, 14, 5)
POUR_REGS_DECLARE(OPAMP);
#define POUR_OPAMP_N_REGS (0x24 / 4)

/* Configures and enables the three with their outputs on the pins: gain 0, the external network on VINM0;
 * gain 2, 4, 8, 16, 32 or 64, non-inverting PGAs. POUR_EINVAL for another gain. */
pour_status_t pour_opamp_init(volatile uint32_t *regs, uint32_t gain);

#endif /* POUR_OPAMP_H */
