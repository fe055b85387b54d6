/* SPDX-License-Identifier: MIT */
/* TIM4 in encoder mode against a register file: x4 quadrature, filters, direction, the 16-bit count. */
#include <string.h>

#include "encoder_tim4.h"
#include "unity.h"

static uint32_t regs[POUR_TIM4_N_REGS];

void setUp(void) { memset(regs, 0xA5, sizeof regs); }

void tearDown(void) {}

static void test_encoder_init_CountsBothEdgesOfBothChannels(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_encoder_init(regs, 6u, 0));
  TEST_ASSERT_EQUAL_HEX32(3u, regs[POUR_TIM4_SMCR]);
  TEST_ASSERT_EQUAL_HEX32(1u | (6u << 4) | (1u << 8) | (6u << 12), regs[POUR_TIM4_CCMR1_INPUT]);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM4_CCER]);
  TEST_ASSERT_EQUAL_HEX32(0xFFFFu, regs[POUR_TIM4_ARR]);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM4_CNT]);
  TEST_ASSERT_EQUAL_HEX32(1u, regs[POUR_TIM4_CR1]);
}

static void test_encoder_init_ReversedInvertsChannelOne(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_encoder_init(regs, 0u, 1));
  TEST_ASSERT_EQUAL_HEX32(1u << 1, regs[POUR_TIM4_CCER]);
}

static void test_encoder_count_ReadsSixteenBits(void) {
  regs[POUR_TIM4_CNT] = 0x0001FFFEu; /* the G4's counter register has more bits: UIFCPY and dithering */
  TEST_ASSERT_EQUAL_HEX16(0xFFFEu, pour_encoder_count(regs));
}

static void test_encoder_init_RefusesABadFilter(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_encoder_init(regs, 16u, 0));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_encoder_init(NULL, 0u, 0));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_encoder_init_CountsBothEdgesOfBothChannels);
  RUN_TEST(test_encoder_init_ReversedInvertsChannelOne);
  RUN_TEST(test_encoder_count_ReadsSixteenBits);
  RUN_TEST(test_encoder_init_RefusesABadFilter);
  return UNITY_END();
}
