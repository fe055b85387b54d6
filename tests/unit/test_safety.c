/* SPDX-License-Identifier: MIT */
#include "pour/safety.h"
#include "unity.h"

static pour_safety_config_t config;
static pour_safety_t safety;

#define MID_URAD 1000000 /* well inside the angle limits */

void setUp(void) {
  config = pour_safety_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
}

void tearDown(void) {}

static void test_safety_init_StartsAtZeroTorque(void) {
  TEST_ASSERT_EQUAL_INT16(0, safety.torque);
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
}

static void test_safety_init_RefusesBadConfigs(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(NULL, &config));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, NULL));
  config.tau_limit = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.slew_per_tick = -1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.theta_max_urad = config.theta_min_urad;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
}

static void test_safety_default_SwingsFullScaleInAbout20Ticks(void) {
  unsigned ticks = 0;
  (void)pour_safety_apply(&safety, POUR_Q15_MIN, MID_URAD);
  pour_safety_force(&safety, POUR_Q15_MIN);
  while (safety.torque != POUR_Q15_MAX && ticks < 100u) {
    (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD);
    ++ticks;
  }
  TEST_ASSERT_EQUAL_UINT(20u, ticks);
}

static void test_safety_apply_SlewLimitsEachStep(void) {
  const q15_t t1 = pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD);
  TEST_ASSERT_EQUAL_INT16(config.slew_per_tick, t1);
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_SLEW, safety.active);
  const q15_t t2 = pour_safety_apply(&safety, POUR_Q15_MIN, MID_URAD);
  TEST_ASSERT_EQUAL_INT16(0, t2);
  const q15_t t3 = pour_safety_apply(&safety, 100, MID_URAD);
  TEST_ASSERT_EQUAL_INT16(100, t3);
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
}

static void test_safety_apply_ClampsToTauLimit(void) {
  config.tau_limit = 10000;
  config.slew_per_tick = POUR_Q15_MAX;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
  TEST_ASSERT_EQUAL_INT16(10000, pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_CLAMP, safety.active);
  TEST_ASSERT_EQUAL_INT16(-10000, pour_safety_apply(&safety, POUR_Q15_MIN, MID_URAD));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_CLAMP, safety.active);
}

static void test_safety_apply_RefusesForwardTorqueAtMaxAngle(void) {
  config.slew_per_tick = POUR_Q15_MAX;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
  TEST_ASSERT_EQUAL_INT16(0, pour_safety_apply(&safety, 20000, config.theta_max_urad));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_ANGLE_MAX, safety.active);
  TEST_ASSERT_EQUAL_INT16(0, pour_safety_apply(&safety, 20000, INT32_MAX));
  /* pulling back is allowed */
  TEST_ASSERT_EQUAL_INT16(-20000, pour_safety_apply(&safety, -20000, config.theta_max_urad));
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
}

static void test_safety_apply_RefusesBackwardTorqueAtMinAngle(void) {
  config.slew_per_tick = POUR_Q15_MAX;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
  TEST_ASSERT_EQUAL_INT16(0, pour_safety_apply(&safety, -20000, config.theta_min_urad));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_ANGLE_MIN, safety.active);
  TEST_ASSERT_EQUAL_INT16(0, pour_safety_apply(&safety, -20000, INT32_MIN));
  TEST_ASSERT_EQUAL_INT16(20000, pour_safety_apply(&safety, 20000, config.theta_min_urad));
}

static void test_safety_apply_DropsTorqueAtLimitWithoutWaitingForSlew(void) {
  for (unsigned i = 0; i < 30u; ++i) {
    (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD);
  }
  TEST_ASSERT_EQUAL_INT16(POUR_Q15_MAX, safety.torque);
  /* reaching the limit: a slewed command would still push forward; it must be zero at once */
  TEST_ASSERT_EQUAL_INT16(0, pour_safety_apply(&safety, POUR_Q15_MAX, config.theta_max_urad + 1));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_ANGLE_MAX, safety.active);
}

static void test_safety_force_BypassesSlew(void) {
  for (unsigned i = 0; i < 30u; ++i) {
    (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD);
  }
  pour_safety_force(&safety, 0);
  TEST_ASSERT_EQUAL_INT16(0, safety.torque);
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
  /* and the slew continues from the forced value */
  TEST_ASSERT_EQUAL_INT16(config.slew_per_tick, pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_safety_init_StartsAtZeroTorque);
  RUN_TEST(test_safety_init_RefusesBadConfigs);
  RUN_TEST(test_safety_default_SwingsFullScaleInAbout20Ticks);
  RUN_TEST(test_safety_apply_SlewLimitsEachStep);
  RUN_TEST(test_safety_apply_ClampsToTauLimit);
  RUN_TEST(test_safety_apply_RefusesForwardTorqueAtMaxAngle);
  RUN_TEST(test_safety_apply_RefusesBackwardTorqueAtMinAngle);
  RUN_TEST(test_safety_apply_DropsTorqueAtLimitWithoutWaitingForSlew);
  RUN_TEST(test_safety_force_BypassesSlew);
  return UNITY_END();
}
