/* SPDX-License-Identifier: MIT */
/* TIM1's three-phase PWM against a register file in plain memory: dead-time codes, the centre-aligned
 * complementary set-up with the ADC trigger at the top, the comparators into the break, compares clamped
 * to the period, gates on and off, and what a break (flag and MOE as the hardware leaves them) does. */
#include <string.h>

#include "pwm_tim1.h"
#include "unity.h"

static uint32_t regs[POUR_TIM1_N_REGS];
static pour_pwm_t pwm;

void setUp(void) {
  memset(regs, 0, sizeof regs);
  const pour_pwm_config_t c = pour_pwm_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_pwm_init(&pwm, regs, &c));
}

void tearDown(void) {}

static void test_pwm_deadtime_code_RoundsUpInBothRanges(void) {
  TEST_ASSERT_EQUAL_INT32(85, pour_pwm_deadtime_code(170000000u, 500u));    /* 500 ns = 85 x 5.88 ns */
  TEST_ASSERT_EQUAL_INT32(86, pour_pwm_deadtime_code(170000000u, 501u));    /* never shorter */
  TEST_ASSERT_EQUAL_INT32(127, pour_pwm_deadtime_code(170000000u, 747u));
  TEST_ASSERT_EQUAL_INT32(0x80 | 21, pour_pwm_deadtime_code(170000000u, 1000u)); /* (64 + 21) x 2 = 170 */
  TEST_ASSERT_EQUAL_INT32(-1, pour_pwm_deadtime_code(170000000u, 0u));
  TEST_ASSERT_EQUAL_INT32(-1, pour_pwm_deadtime_code(170000000u, 2000u)); /* beyond 2 x 127 periods */
}

static void test_pwm_init_IsCentreAlignedComplementaryWithTheTriggerAtTheTop(void) {
  TEST_ASSERT_EQUAL_UINT16(4250u, pwm.period); /* 170 MHz / (2 x 20 kHz) */
  TEST_ASSERT_EQUAL_HEX32(4250u, regs[POUR_TIM1_ARR]);
  TEST_ASSERT_EQUAL_HEX32((1u << 5) | (1u << 7) | 1u, regs[POUR_TIM1_CR1]); /* CMS 01, ARPE, CEN */
  TEST_ASSERT_EQUAL_HEX32(4249u, regs[POUR_TIM1_CCR4]);
  /* PWM mode 1 with preload on CH1..CH4 */
  TEST_ASSERT_EQUAL_HEX32((6u << 4) | (1u << 3) | (6u << 12) | (1u << 11), regs[POUR_TIM1_CCMR1_OUTPUT]);
  TEST_ASSERT_EQUAL_HEX32((6u << 4) | (1u << 3) | (6u << 12) | (1u << 11), regs[POUR_TIM1_CCMR2_OUTPUT]);
  /* TRGO2 = OC4REF; idle levels: all six off (OISx = OISxN = 0, ST's for this board) */
  TEST_ASSERT_EQUAL_HEX32(7u << 20, regs[POUR_TIM1_CR2]);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_CCER]); /* all six off */
  TEST_ASSERT_EQUAL_HEX32((1u << 1) | (1u << 2) | (1u << 4), regs[POUR_TIM1_AF1]); /* COMP1, 2, 4 */
  /* DTG 800 ns = 136 clocks = (64 + 4) x 2, OSSI, OSSR, BKE, BKP, no AOE, MOE, BKF 6 (141 ns) */
  TEST_ASSERT_EQUAL_HEX32((0x80u | 4u) | (1u << 10) | (1u << 11) | (1u << 12) | (1u << 13) | (1u << 15) | (6u << 16),
                          regs[POUR_TIM1_BDTR]);
  TEST_ASSERT_FALSE(pour_pwm_enabled(&pwm));
}

static void test_pwm_init_RefusesBadConfig(void) {
  pour_pwm_config_t c = pour_pwm_default_config();
  c.pwm_hz = 10000u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_pwm_init(&pwm, regs, &c));
  c = pour_pwm_default_config();
  c.deadtime_ns = 1400u; /* codeable, but 2.8 % of 20 kHz is fine; at 40 kHz 5.6 % is not */
  c.pwm_hz = 40000u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_pwm_init(&pwm, regs, &c));
  c = pour_pwm_default_config();
  c.break_filter = 16u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_pwm_init(&pwm, regs, &c));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_pwm_init(&pwm, NULL, &c));
}

static void test_pwm_set_compares_ClampsToThePeriod(void) {
  const uint16_t c[3] = {100u, 4250u, 60000u};
  pour_pwm_set_compares(&pwm, c);
  TEST_ASSERT_EQUAL_HEX32(100u, regs[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_HEX32(4250u, regs[POUR_TIM1_CCR2]);
  TEST_ASSERT_EQUAL_HEX32(4250u, regs[POUR_TIM1_CCR3]);
}

static void test_pwm_enable_SwitchesTheBridgeChannels(void) {
  pour_pwm_enable(&pwm, true);
  TEST_ASSERT_EQUAL_HEX32(0x555u, regs[POUR_TIM1_CCER]); /* CC1E/NE, CC2E/NE, CC3E/NE */
  TEST_ASSERT_TRUE(pour_pwm_enabled(&pwm));
  pour_pwm_enable(&pwm, false);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_CCER]);
  TEST_ASSERT_FALSE(pour_pwm_enabled(&pwm));
}

static void test_pwm_break_LeavesTheBridgeOffUntilCleared(void) {
  const uint16_t c[3] = {2000u, 2000u, 2000u};
  pour_pwm_set_compares(&pwm, c);
  pour_pwm_enable(&pwm, true);
  regs[POUR_TIM1_SR] |= 1u << 7;     /* the hardware: BIF set */
  regs[POUR_TIM1_BDTR] &= ~(1u << 15); /* and MOE cleared: outputs at their idle levels */
  TEST_ASSERT_TRUE(pour_pwm_break_fired(&pwm));
  TEST_ASSERT_FALSE(pour_pwm_enabled(&pwm));
  pour_pwm_short_low_sides(&pwm);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_BDTR] & (1u << 15)); /* software never sets MOE during a break */
  pour_pwm_clear_break(&pwm);
  TEST_ASSERT_FALSE(pour_pwm_break_fired(&pwm));
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_CCER]); /* re-armed with all six off */
  TEST_ASSERT_EQUAL_HEX32(1u << 15, regs[POUR_TIM1_BDTR] & (1u << 15));
}

static void test_pwm_short_low_sides_ZeroesTheComparesNow(void) {
  const uint16_t c[3] = {2000u, 1000u, 3000u};
  pour_pwm_set_compares(&pwm, c);
  regs[POUR_TIM1_EGR] = 0u;
  pour_pwm_short_low_sides(&pwm);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_CCR2]);
  TEST_ASSERT_EQUAL_HEX32(1u, regs[POUR_TIM1_EGR]); /* an update now, not at the period's end */
  TEST_ASSERT_TRUE(pour_pwm_enabled(&pwm));
}

/* A faulted drive calls it on every interrupt: UG restarts the counter (RM0440), so only the first call may
 * generate one, and a compare or an enable in between makes the next short a new one. */
static void test_pwm_short_low_sides_UpdatesOnlyOnEnteringTheShort(void) {
  const uint16_t c[3] = {2000u, 1000u, 3000u};
  pour_pwm_set_compares(&pwm, c);
  pour_pwm_short_low_sides(&pwm);
  regs[POUR_TIM1_EGR] = 0u; /* write-only on the chip: the memory keeps the last write */
  pour_pwm_short_low_sides(&pwm);
  pour_pwm_short_low_sides(&pwm);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_EGR]);
  TEST_ASSERT_TRUE(pour_pwm_enabled(&pwm));
  pour_pwm_set_compares(&pwm, c);
  pour_pwm_short_low_sides(&pwm);
  TEST_ASSERT_EQUAL_HEX32(1u, regs[POUR_TIM1_EGR]);
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_TIM1_CCR1]);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_pwm_deadtime_code_RoundsUpInBothRanges);
  RUN_TEST(test_pwm_init_IsCentreAlignedComplementaryWithTheTriggerAtTheTop);
  RUN_TEST(test_pwm_init_RefusesBadConfig);
  RUN_TEST(test_pwm_set_compares_ClampsToThePeriod);
  RUN_TEST(test_pwm_enable_SwitchesTheBridgeChannels);
  RUN_TEST(test_pwm_break_LeavesTheBridgeOffUntilCleared);
  RUN_TEST(test_pwm_short_low_sides_ZeroesTheComparesNow);
  RUN_TEST(test_pwm_short_low_sides_UpdatesOnlyOnEnteringTheShort);
  return UNITY_END();
}
