/* SPDX-License-Identifier: MIT */
/* ADC1 and ADC2: injected conversions started by TIM1's TRGO2 at the top of the PWM count (pwm_tim1.h),
 * the three phase currents (the op-amps' outputs on their pins) and the bus voltage and NTC, read by the
 * current loop's interrupt at the end of the sequence. On the B-G431B-ESC1:
 *   ADC1: IN3 (PA2, OPAMP1: U), IN12 (PB1, OPAMP3: W), IN1 (PA0, bus divider), IN5 (PB14, NTC)
 *   ADC2: IN3 (PA6, OPAMP2: V)
 * U and V are sampled at the same instant, W one conversion (0.44 µs) later, all in the low-side window.
 * Registers through pointers (register files in tests/board/test_board_adc.c). */
#ifndef POUR_ADC_INJ_H
#define POUR_ADC_INJ_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"
#include "regs.h"

#define POUR_ADC_PERIPHS(P) P(ADC1, ADC, 0x50000000) P(ADC2, ADC, 0x50000100) P(ADC12_COMMON, ADC12, 0x50000300)
#define POUR_ADC_REGS(R)                                                                                       \
  R(ADC, ISR, 0x00)                                                                                            \
  R(ADC, IER, 0x04)                                                                                            \
  R(ADC, CR, 0x08)                                                                                             \
  R(ADC, CFGR, 0x0C)                                                                                           \
  R(ADC, SMPR1, 0x14)                                                                                          \
  R(ADC, SMPR2, 0x18)                                                                                          \
  R(ADC, JSQR, 0x4C)                                                                                           \
  R(ADC, JDR1, 0x80)                                                                                           \
  R(ADC, JDR2, 0x84)                                                                                           \
  R(ADC, JDR3, 0x88)                                                                                           \
  R(ADC, JDR4, 0x8C)                                                                                           \
  R(ADC12, CCR, 0x08)
#define POUR_ADC_FIELDS(F)                                                                                     \
  F(ADC, ISR, ADRDY, 0, 1)                                                                                     \
  F(ADC, ISR, JEOC, 5, 1)                                                                                      \
  F(ADC, ISR, JEOS, 6, 1)                                                                                      \
  F(ADC, IER, JEOSIE, 6, 1)                                                                                    \
  F(ADC, CR, ADEN, 0, 1)                                                                                       \
  F(ADC, CR, JADSTART, 3, 1)                                                                                   \
  F(ADC, CR, ADVREGEN, 28, 1)                                                                                  \
  F(ADC, CR, DEEPPWD, 29, 1)                                                                                   \
  F(ADC, CR, ADCALDIF, 30, 1)                                                                                  \
  F(ADC, CR, ADCAL, 31, 1)                                                                                     \
  F(ADC, CFGR, JQDIS, 31, 1)                                                                                   \
  F(ADC, SMPR1, SMP0, 0, 3)                                                                                    \
  F(ADC, SMPR1, SMP9, 27, 3)                                                                                   \
  F(ADC, SMPR2, SMP10, 0, 3)                                                                                   \
  F(ADC, SMPR2, SMP18, 24, 3)                                                                                  \
  F(ADC, JSQR, JL, 0, 2)                                                                                       \
  F(ADC, JSQR, JEXTSEL, 2, 5)                                                                                  \
  F(ADC, JSQR, JEXTEN, 7, 2)                                                                                   \
  F(ADC, JSQR, JSQ1, 9, 5)                                                                                     \
  F(ADC, JSQR, JSQ2, 15, 5)                                                                                    \
  F(ADC, JSQR, JSQ3, 21, 5)                                                                                    \
  F(ADC, JSQR, JSQ4, 27, 5)                                                                                    \
  F(ADC, JDR1, JDATA, 0, 16)                                                                                   \
  F(ADC12, CCR, CKMODE, 16, 2)                                                                                 \
  F(ADC12, CCR, DUAL, 0, 5)
POUR_REGS_DECLARE(ADC);
#define POUR_ADC_N_REGS (0x100 / 4)   /* one ADC's register file in a host test [words] */

/* ADC1 and ADC2's interrupt line (the stm32g4 crate's Interrupt::ADC1_2): the current loop's. */
#define POUR_ADC_IRQ 18u

/* RM0440 (not in the SVD): injected trigger 8 of ADC1/ADC2 is TIM1's TRGO2; ADC12 clock HCLK / 4. */
#define POUR_ADC_JEXTSEL_TIM1_TRGO2 8u
#define POUR_ADC_CKMODE_HCLK_DIV4 3u

typedef struct {
  uint16_t phase[3]; /* U, V, W op-amp outputs [12-bit counts] */
  uint16_t vbus;     /* bus divider [counts] */
  uint16_t ntc;      /* power-stage NTC divider [counts] */
} pour_adc_sample_t;

typedef struct {
  volatile uint32_t *adc1, *adc2, *common;
  uint32_t ready_polls; /* bound of each wait for the hardware (calibration, ADRDY) */
} pour_adc_t;

/* Regulator on, calibration, enable, the injected sequences, trigger armed; the end-of-sequence interrupt
 * of ADC1 enabled (the current loop). regulator_wait: core loop iterations for the regulator's 20 µs start-up.
 * POUR_EINVAL if a flag never comes (within ready_polls). */
pour_status_t pour_adc_init(pour_adc_t *adc, volatile uint32_t *adc1, volatile uint32_t *adc2, volatile uint32_t *common,
                            uint32_t ready_polls, uint32_t regulator_wait);

/* The enabled converters' sample times, sequences and trigger, armed (part of pour_adc_init). */
void pour_adc_configure(pour_adc_t *adc);

/* true once this period's sequence is complete (ADC1 JEOS); the sample is read and the flag cleared. */
bool pour_adc_read(pour_adc_t *adc, pour_adc_sample_t *sample);

#endif /* POUR_ADC_INJ_H */
