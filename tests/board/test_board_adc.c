/* SPDX-License-Identifier: MIT */
/* ADC1/ADC2 injected conversions against register files in plain memory: the sequences, sample times and
 * TIM1 TRGO2 trigger, a calibration that never ends, and one period's sample read and acknowledged. */
#include <string.h>

#include "adc_inj.h"
#include "unity.h"

static uint32_t adc1[POUR_ADC_N_REGS], adc2[POUR_ADC_N_REGS], common[0x10 / 4];
static pour_adc_t adc;

void setUp(void) {
  memset(adc1, 0, sizeof adc1);
  memset(adc2, 0, sizeof adc2);
  memset(common, 0, sizeof common);
  adc.adc1 = adc1;
  adc.adc2 = adc2;
  adc.common = common;
  adc.ready_polls = 10u;
}

void tearDown(void) {}

static void test_adc_configure_SequencesCurrentsFirstOnTheTim1Trigger(void) {
  pour_adc_configure(&adc);
  /* ADC1: JL 3 (4 ranks), JEXTSEL 8, rising, IN3, IN12, IN1, IN5 */
  TEST_ASSERT_EQUAL_HEX32(3u | (8u << 2) | (1u << 7) | (3u << 9) | (12u << 15) | (1u << 21) | (5u << 27),
                          adc1[POUR_ADC_JSQR]);
  TEST_ASSERT_EQUAL_HEX32(0u | (8u << 2) | (1u << 7) | (3u << 9), adc2[POUR_ADC_JSQR]);
  TEST_ASSERT_EQUAL_HEX32((4u << 3) | (1u << 9) | (4u << 15), adc1[POUR_ADC_SMPR1]); /* IN1, IN3, IN5 */
  TEST_ASSERT_EQUAL_HEX32(1u << 6, adc1[POUR_ADC_SMPR2]);                          /* IN12 */
  TEST_ASSERT_EQUAL_HEX32(1u << 9, adc2[POUR_ADC_SMPR1]);
  TEST_ASSERT_EQUAL_HEX32(1u << 6, adc1[POUR_ADC_IER]); /* JEOSIE: the current loop's interrupt */
  TEST_ASSERT_EQUAL_HEX32(1u << 3, adc1[POUR_ADC_CR] & (1u << 3));
  TEST_ASSERT_EQUAL_HEX32(1u << 3, adc2[POUR_ADC_CR] & (1u << 3));
}

static void test_adc_init_RefusesACalibrationThatNeverEnds(void) {
  /* ADCAL stays set in plain memory, as it would on a converter without its clock. */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_adc_init(&adc, adc1, adc2, common, 10u, 0u));
  TEST_ASSERT_EQUAL_HEX32(3u << 16, common[POUR_ADC12_CCR]); /* HCLK / 4 = 42.5 MHz */
  TEST_ASSERT_EQUAL_HEX32(0u, adc1[POUR_ADC_JSQR]);         /* nothing armed */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_adc_init(&adc, adc1, adc2, common, 0u, 0u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_adc_init(&adc, NULL, adc2, common, 10u, 0u));
}

static void test_adc_read_MapsRanksToPhasesAndAcknowledges(void) {
  pour_adc_sample_t s;
  TEST_ASSERT_FALSE(pour_adc_read(&adc, &s));
  adc1[POUR_ADC_JDR1] = 2100u; /* U */
  adc1[POUR_ADC_JDR2] = 1990u; /* W */
  adc1[POUR_ADC_JDR3] = 1500u; /* bus */
  adc1[POUR_ADC_JDR4] = 1200u; /* NTC */
  adc2[POUR_ADC_JDR1] = 2050u; /* V */
  adc1[POUR_ADC_ISR] = (1u << 5) | (1u << 6);
  TEST_ASSERT_TRUE(pour_adc_read(&adc, &s));
  TEST_ASSERT_EQUAL_UINT16(2100u, s.phase[0]);
  TEST_ASSERT_EQUAL_UINT16(2050u, s.phase[1]);
  TEST_ASSERT_EQUAL_UINT16(1990u, s.phase[2]);
  TEST_ASSERT_EQUAL_UINT16(1500u, s.vbus);
  TEST_ASSERT_EQUAL_UINT16(1200u, s.ntc);
  TEST_ASSERT_EQUAL_HEX32((1u << 5) | (1u << 6), adc2[POUR_ADC_ISR]); /* write-1-to-clear of both */
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_adc_configure_SequencesCurrentsFirstOnTheTim1Trigger);
  RUN_TEST(test_adc_init_RefusesACalibrationThatNeverEnds);
  RUN_TEST(test_adc_read_MapsRanksToPhasesAndAcknowledges);
  return UNITY_END();
}
