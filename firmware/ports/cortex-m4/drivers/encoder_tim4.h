/* SPDX-License-Identifier: MIT */
/* TIM4 as the motor encoder's quadrature counter (J8: A on PB6 = CH1, B on PB7 = CH2), both edges of both
 * channels (x4), a digital filter against ringing on the cable; the 16-bit count wraps and is read as it is
 * (the motor library takes differences modulo 2^16). */
#ifndef POUR_ENCODER_TIM4_H
#define POUR_ENCODER_TIM4_H

#include <stdint.h>

#include "pour/fixed.h"
#include "regs.h"

#define POUR_TIM4_PERIPHS(P) P(TIM4, TIM4, 0x40000800)
#define POUR_TIM4_REGS(R)                                                                                      \
  R(TIM4, CR1, 0x00)                                                                                           \
  R(TIM4, SMCR, 0x08)                                                                                          \
  R(TIM4, CCMR1_INPUT, 0x18)                                                                                   \
  R(TIM4, CCER, 0x20)                                                                                          \
  R(TIM4, CNT, 0x24)                                                                                           \
  R(TIM4, ARR, 0x2C)
#define POUR_TIM4_FIELDS(F)                                                                                    \
  F(TIM4, CR1, CEN, 0, 1)                                                                                      \
  F(TIM4, SMCR, SMS, 0, 3)                                                                                     \
  F(TIM4, SMCR, SMS_3, 16, 1)                                                                                  \
  F(TIM4, CCMR1_INPUT, CC1S, 0, 2)                                                                             \
  F(TIM4, CCMR1_INPUT, IC1F, 4, 4)                                                                             \
  F(TIM4, CCMR1_INPUT, CC2S, 8, 2)                                                                             \
  F(TIM4, CCMR1_INPUT, IC2F, 12, 4)                                                                            \
  F(TIM4, CCER, CC1P, 1, 1)                                                                                    \
  F(TIM4, CCER, CC2P, 5, 1)                                                                                    \
  F(TIM4, CNT, CNT, 0, 16)                                                                                     \
  F(TIM4, ARR, ARR, 0, 20)
POUR_REGS_DECLARE(TIM4);
#define POUR_TIM4_N_REGS (0x30 / 4)

/* Encoder mode 3 (x4), input filter filter (IC1F/IC2F code 0 .. 15), reversed: count the other way (the
 * calibration's encoder direction). POUR_EINVAL for a bad filter. */
pour_status_t pour_encoder_init(volatile uint32_t *regs, uint32_t filter, int reversed);

/* The count, modulo 2^16. */
uint16_t pour_encoder_count(const volatile uint32_t *regs);

#endif /* POUR_ENCODER_TIM4_H */
