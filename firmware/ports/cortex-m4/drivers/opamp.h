/* SPDX-License-Identifier: MIT */
/* OPAMP1..3, the phase shunts' amplifiers (B-G431B-ESC1, pour/board_facts.h: VINP0 on PA1, PA7, PB0 carries the
 * shunt through the board's network, VINM0 on PA3, PA5, PB2 its foot; outputs on PA2, PA6, PB1 into the ADCs):
 * internal programmable-gain amplifiers whose gain network's foot is VINM0 ("input/bias on VINM0"), as ST's
 * own project for this board sets them (x16 there: 9.14 from the shunt with the network's 0.571), in
 * high-speed mode (FOC-Stim's choice for this board; ST's project uses normal speed). */
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

/* Configures and enables the three with their outputs on the pins: non-inverting PGAs of gain 2, 4, 8, 16, 32
 * or 64 with the input/bias on VINM0. POUR_EINVAL for another gain. */
pour_status_t pour_opamp_init(volatile uint32_t *regs, uint32_t gain);

#endif /* POUR_OPAMP_H */
