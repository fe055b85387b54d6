/* SPDX-License-Identifier: MIT */
#include "pour/current_pi.h"
#include "unity.h"

static pour_current_pi_t pi;

void setUp(void) {
  /* ωc = 3000 rad/s, L = 231.5 µH, R = 0.304 Ω, 20 kHz, bases 64 A and 64 V */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_current_pi_init(&pi, 3000, 231500, 304000, 20000, 64000, 64000));
}
void tearDown(void) {}

static void test_current_pi_GainsAreBandwidthTimesLAndR(void) {
  TEST_ASSERT_EQUAL_INT32(45515, pi.kp_q16); /* 0.6945 V/A · 65536 */
  TEST_ASSERT_EQUAL_INT32(2988, pi.ki_q16);  /* 3000 · 0.304 / 20000 = 0.0456 · 65536 */
}

static void test_current_pi_IntegratesAConstantError(void) {
  const q15_t u1 = pour_current_pi_step(&pi, 1000, 30000);
  const q15_t u2 = pour_current_pi_step(&pi, 1000, 30000);
  TEST_ASSERT_EQUAL_INT16(695 + 46, u1); /* Kp·e + Ki·Ts·e */
  TEST_ASSERT_EQUAL_INT16(695 + 91, u2);
}

static void test_current_pi_OutputStaysWithinTheLimit(void) {
  for (int k = 0; k < 1000; ++k) {
    const q15_t u = pour_current_pi_step(&pi, 30000, 2000);
    TEST_ASSERT_TRUE(u <= 2000 && u >= -2000);
  }
  TEST_ASSERT_EQUAL_INT16(-2000, pour_current_pi_step(&pi, -65535, 2000));
}

static void test_current_pi_AntiWindupRecoversAtOnce(void) {
  /* saturated for 1000 periods, then the error reverses: the output leaves the limit on the next period */
  for (int k = 0; k < 1000; ++k) (void)pour_current_pi_step(&pi, 5000, 2000);
  TEST_ASSERT_TRUE(pi.integ_q16 <= 2000 * 65536);
  const q15_t u = pour_current_pi_step(&pi, -500, 2000);
  TEST_ASSERT_TRUE(u < 2000);
}

static void test_current_pi_RefusesGainsThatDoNotFit(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_current_pi_init(&pi, 3000, 0, 304000, 20000, 64000, 64000));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_current_pi_init(&pi, 3000, 231500, 304000, 0, 64000, 64000));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_current_pi_init(&pi, 4000000000u, 4000000000u, 304000, 20000, 64000, 64000));
}

static void test_current_pi_ResetEmptiesTheIntegrator(void) {
  (void)pour_current_pi_step(&pi, 1000, 30000);
  pour_current_pi_reset(&pi);
  TEST_ASSERT_EQUAL_INT32(0, pi.integ_q16);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_current_pi_GainsAreBandwidthTimesLAndR);
  RUN_TEST(test_current_pi_IntegratesAConstantError);
  RUN_TEST(test_current_pi_OutputStaysWithinTheLimit);
  RUN_TEST(test_current_pi_AntiWindupRecoversAtOnce);
  RUN_TEST(test_current_pi_RefusesGainsThatDoNotFit);
  RUN_TEST(test_current_pi_ResetEmptiesTheIntegrator);
  return UNITY_END();
}
