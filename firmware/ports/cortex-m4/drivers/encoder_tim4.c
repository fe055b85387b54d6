/* SPDX-License-Identifier: MIT */
#include "encoder_tim4.h"

#include <stddef.h>

#define SMS_ENCODER_X4 3u /* counts on TI1 and TI2 edges */
#define CCS_TI 1u         /* CCx input, mapped on TIx */

pour_status_t pour_encoder_init(volatile uint32_t *regs, uint32_t filter, int reversed) {
  if (regs == NULL || filter > 15u) {
    return POUR_EINVAL;
  }
  regs[POUR_TIM4_CR1] = 0u;
  regs[POUR_TIM4_SMCR] = POUR_VAL(TIM4, SMCR, SMS, SMS_ENCODER_X4);
  regs[POUR_TIM4_CCMR1_INPUT] = POUR_VAL(TIM4, CCMR1_INPUT, CC1S, CCS_TI) | POUR_VAL(TIM4, CCMR1_INPUT, IC1F, filter) |
                                POUR_VAL(TIM4, CCMR1_INPUT, CC2S, CCS_TI) | POUR_VAL(TIM4, CCMR1_INPUT, IC2F, filter);
  regs[POUR_TIM4_CCER] = reversed ? POUR_MSK(TIM4, CCER, CC1P) : 0u; /* TI1 inverted: the count runs backwards */
  regs[POUR_TIM4_ARR] = 0xFFFFu;
  regs[POUR_TIM4_CNT] = 0u;
  regs[POUR_TIM4_CR1] = POUR_MSK(TIM4, CR1, CEN);
  return POUR_OK;
}

uint16_t pour_encoder_count(const volatile uint32_t *regs) { return (uint16_t)POUR_GET(TIM4, CNT, CNT, regs[POUR_TIM4_CNT]); }
