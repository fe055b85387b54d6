/* SPDX-License-Identifier: MIT */
#include "adc_inj.h"

#include <stddef.h>

#define JEXTEN_RISING 1u
#define SMP_6C5 1u  /* 6.5 cycles: the op-amps' low-impedance outputs */
#define SMP_47C5 4u /* 47.5 cycles: the bus divider and the NTC (high impedance) */
#define CH_U 3u
#define CH_W 12u
#define CH_VBUS 1u
#define CH_NTC 5u
#define CH_V 3u
#define SMP_WIDTH 3u

static void sample_time(volatile uint32_t *r, uint32_t channel, uint32_t smp) {
  volatile uint32_t *reg = channel < 10u ? &r[POUR_ADC_SMPR1] : &r[POUR_ADC_SMPR2];
  const uint32_t shift = SMP_WIDTH * (channel % 10u);
  *reg = (*reg & ~(7u << shift)) | (smp << shift);
}

static pour_status_t bring_up(volatile uint32_t *r, uint32_t polls, uint32_t regulator_wait) {
  r[POUR_ADC_CR] = 0u; /* leave deep power-down */
  r[POUR_ADC_CR] = POUR_MSK(ADC, CR, ADVREGEN);
  for (volatile uint32_t i = 0; i < regulator_wait; ++i) {
  }
  r[POUR_ADC_CR] = POUR_MSK(ADC, CR, ADVREGEN) | POUR_MSK(ADC, CR, ADCAL); /* single-ended calibration */
  if (pour_regs_wait(&r[POUR_ADC_CR], POUR_MSK(ADC, CR, ADCAL), 0u, polls) != 0) {
    return POUR_EINVAL;
  }
  r[POUR_ADC_ISR] = POUR_MSK(ADC, ISR, ADRDY); /* write 1 to clear */
  r[POUR_ADC_CR] = POUR_MSK(ADC, CR, ADVREGEN) | POUR_MSK(ADC, CR, ADEN);
  if (pour_regs_wait(&r[POUR_ADC_ISR], POUR_MSK(ADC, ISR, ADRDY), POUR_MSK(ADC, ISR, ADRDY), polls) != 0) {
    return POUR_EINVAL;
  }
  r[POUR_ADC_CFGR] = POUR_MSK(ADC, CFGR, JQDIS); /* JSQR is the sequence, no queue of contexts */
  return POUR_OK;
}

static uint32_t jsqr(uint32_t length, uint32_t c1, uint32_t c2, uint32_t c3, uint32_t c4) {
  return POUR_VAL(ADC, JSQR, JL, length - 1u) | POUR_VAL(ADC, JSQR, JEXTSEL, POUR_ADC_JEXTSEL_TIM1_TRGO2) |
         POUR_VAL(ADC, JSQR, JEXTEN, JEXTEN_RISING) | POUR_VAL(ADC, JSQR, JSQ1, c1) | POUR_VAL(ADC, JSQR, JSQ2, c2) |
         POUR_VAL(ADC, JSQR, JSQ3, c3) | POUR_VAL(ADC, JSQR, JSQ4, c4);
}

pour_status_t pour_adc_init(pour_adc_t *adc, volatile uint32_t *adc1, volatile uint32_t *adc2, volatile uint32_t *common,
                            uint32_t ready_polls, uint32_t regulator_wait) {
  if (adc == NULL || adc1 == NULL || adc2 == NULL || common == NULL || ready_polls == 0u) {
    return POUR_EINVAL;
  }
  adc->adc1 = adc1;
  adc->adc2 = adc2;
  adc->common = common;
  adc->ready_polls = ready_polls;
  /* Independent mode: both follow the same trigger. */
  common[POUR_ADC12_CCR] = POUR_VAL(ADC12, CCR, CKMODE, POUR_ADC_CKMODE_HCLK_DIV4);
  if (bring_up(adc1, ready_polls, regulator_wait) != POUR_OK || bring_up(adc2, ready_polls, regulator_wait) != POUR_OK) {
    return POUR_EINVAL;
  }
  pour_adc_configure(adc);
  return POUR_OK;
}

void pour_adc_configure(pour_adc_t *adc) {
  volatile uint32_t *const adc1 = adc->adc1;
  volatile uint32_t *const adc2 = adc->adc2;
  sample_time(adc1, CH_U, SMP_6C5);
  sample_time(adc1, CH_W, SMP_6C5);
  sample_time(adc1, CH_VBUS, SMP_47C5);
  sample_time(adc1, CH_NTC, SMP_47C5);
  sample_time(adc2, CH_V, SMP_6C5);
  adc1[POUR_ADC_JSQR] = jsqr(4u, CH_U, CH_W, CH_VBUS, CH_NTC);
  adc2[POUR_ADC_JSQR] = jsqr(1u, CH_V, 0u, 0u, 0u);
  adc1[POUR_ADC_ISR] = POUR_MSK(ADC, ISR, JEOC) | POUR_MSK(ADC, ISR, JEOS);
  adc2[POUR_ADC_ISR] = POUR_MSK(ADC, ISR, JEOC) | POUR_MSK(ADC, ISR, JEOS);
  adc1[POUR_ADC_IER] = POUR_MSK(ADC, IER, JEOSIE);
  adc1[POUR_ADC_CR] |= POUR_MSK(ADC, CR, JADSTART); /* armed: each trigger converts the sequence */
  adc2[POUR_ADC_CR] |= POUR_MSK(ADC, CR, JADSTART);
}

static uint16_t data(const volatile uint32_t *r, unsigned rank) {
  return (uint16_t)POUR_GET(ADC, JDR1, JDATA, r[POUR_ADC_JDR1 + rank]);
}

bool pour_adc_read(pour_adc_t *adc, pour_adc_sample_t *sample) {
  if ((adc->adc1[POUR_ADC_ISR] & POUR_MSK(ADC, ISR, JEOS)) == 0u) {
    return false;
  }
  sample->phase[0] = data(adc->adc1, 0u);
  sample->phase[1] = data(adc->adc2, 0u);
  sample->phase[2] = data(adc->adc1, 1u);
  sample->vbus = data(adc->adc1, 2u);
  sample->ntc = data(adc->adc1, 3u);
  adc->adc1[POUR_ADC_ISR] = POUR_MSK(ADC, ISR, JEOC) | POUR_MSK(ADC, ISR, JEOS);
  adc->adc2[POUR_ADC_ISR] = POUR_MSK(ADC, ISR, JEOC) | POUR_MSK(ADC, ISR, JEOS);
  return true;
}
