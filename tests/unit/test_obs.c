/* SPDX-License-Identifier: MIT */
#include "pour/obs.h"
#include "unity.h"

static pour_obs_norm_t norm;
static pour_state_t state;
static pour_obs_t obs;

void setUp(void) {
  norm.theta_min_urad = 0;
  norm.theta_max_urad = 2356194;
  norm.omega_max_urad_s = 4000000;
  state.seq = 0u;
  state.theta_urad = 0;
  state.omega_urad_s = 0;
  state.v_rotating = 0;
  state.v_target = 0;
  state.v_spill = 0;
}

void tearDown(void) {}

static q15_t theta_q15(int32_t theta) {
  state.theta_urad = theta;
  pour_obs_quantize(&norm, &state, &obs);
  return obs.x[0];
}

static q15_t omega_q15(int32_t omega) {
  state.omega_urad_s = omega;
  pour_obs_quantize(&norm, &state, &obs);
  return obs.x[1];
}

static void test_obs_quantize_ThetaEndsMapToZeroAndMax(void) {
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(0));
  TEST_ASSERT_EQUAL_INT16(32767, theta_q15(2356194)); /* 1.0 saturates to the largest Q15 */
  TEST_ASSERT_EQUAL_INT16(16384, theta_q15(1178097)); /* exactly half */
}

static void test_obs_quantize_ThetaSaturatesNeverWraps(void) {
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(INT32_MIN));
  TEST_ASSERT_EQUAL_INT16(32767, theta_q15(INT32_MAX));
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(-1));
  TEST_ASSERT_EQUAL_INT16(32767, theta_q15(2356195));
}

static void test_obs_quantize_RoundsHalfAnLsbUp(void) {
  norm.theta_min_urad = 0;
  norm.theta_max_urad = 65536; /* one µrad = half an LSB */
  TEST_ASSERT_EQUAL_INT16(1, theta_q15(1));     /* 0.5 LSB -> 1 */
  TEST_ASSERT_EQUAL_INT16(2, theta_q15(3));     /* 1.5 LSB -> 2 */
  TEST_ASSERT_EQUAL_INT16(2, theta_q15(4));     /* 2.0 LSB */
  TEST_ASSERT_EQUAL_INT16(32767, theta_q15(65535)); /* 32767.5 LSB -> 32768 -> saturates */
  TEST_ASSERT_EQUAL_INT16(32767, theta_q15(65534));
  norm.theta_max_urad = 3 * 32768; /* 1 µrad = 1/3 LSB */
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(1));     /* 0.33 LSB -> 0 */
  TEST_ASSERT_EQUAL_INT16(1, theta_q15(2));     /* 0.67 LSB -> 1 */
}

static void test_obs_quantize_NegativeThetaMinShiftsTheRange(void) {
  norm.theta_min_urad = -100000;
  norm.theta_max_urad = 100000;
  TEST_ASSERT_EQUAL_INT16(16384, theta_q15(0));
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(-100000));
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(INT32_MIN));
}

static void test_obs_quantize_WidestNormDoesNotOverflow(void) {
  norm.theta_min_urad = INT32_MIN;
  norm.theta_max_urad = INT32_MAX;
  norm.omega_max_urad_s = INT32_MAX;
  TEST_ASSERT_EQUAL_INT16(16384, theta_q15(0));
  TEST_ASSERT_EQUAL_INT16(32767, theta_q15(INT32_MAX));
  TEST_ASSERT_EQUAL_INT16(0, theta_q15(INT32_MIN));
  TEST_ASSERT_EQUAL_INT16(16384, omega_q15(0));
  TEST_ASSERT_EQUAL_INT16(32767, omega_q15(INT32_MAX));
  TEST_ASSERT_EQUAL_INT16(0, omega_q15(INT32_MIN));
}

static void test_obs_quantize_OmegaIsCentredAndSaturates(void) {
  TEST_ASSERT_EQUAL_INT16(16384, omega_q15(0));
  TEST_ASSERT_EQUAL_INT16(0, omega_q15(-4000000));
  TEST_ASSERT_EQUAL_INT16(32767, omega_q15(4000000));
  TEST_ASSERT_EQUAL_INT16(0, omega_q15(INT32_MIN));
  TEST_ASSERT_EQUAL_INT16(32767, omega_q15(INT32_MAX));
  TEST_ASSERT_EQUAL_INT16(24576, omega_q15(2000000));
}

static void test_obs_quantize_NegativeVolumesBecomeZero(void) {
  state.v_rotating = -1;
  state.v_target = INT16_MIN;
  state.v_spill = 32767;
  pour_obs_quantize(&norm, &state, &obs);
  TEST_ASSERT_EQUAL_INT16(0, obs.x[2]);
  TEST_ASSERT_EQUAL_INT16(0, obs.x[3]);
  TEST_ASSERT_EQUAL_INT16(32767, obs.x[4]);
  state.v_rotating = 12345;
  pour_obs_quantize(&norm, &state, &obs);
  TEST_ASSERT_EQUAL_INT16(12345, obs.x[2]);
}

static void test_obs_norm_validate_RefusesEmptyOrInvertedRanges(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_obs_norm_validate(&norm));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_obs_norm_validate(NULL));
  norm.theta_max_urad = norm.theta_min_urad;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_obs_norm_validate(&norm));
  norm.theta_max_urad = norm.theta_min_urad - 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_obs_norm_validate(&norm));
  setUp();
  norm.omega_max_urad_s = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_obs_norm_validate(&norm));
  norm.omega_max_urad_s = -5;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_obs_norm_validate(&norm));
  norm.theta_min_urad = INT32_MIN;
  norm.theta_max_urad = INT32_MAX;
  norm.omega_max_urad_s = INT32_MAX;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_obs_norm_validate(&norm));
}

/* The Q15 of num / den as tools/pour/policy/fixedpoint.py's ratio_q15 writes it: (2 num 32768 + den) // (2 den),
 * clipped to [0, 32767], in int64 (an independent form of what obs.c computes in 32 bits where it can). */
static q15_t reference_q15(int64_t num, int64_t den) {
  if (num <= 0) {
    return 0;
  }
  const int64_t q = (2 * num * 32768 + den) / (2 * den);
  return (q15_t)(q > 32767 ? 32767 : q);
}

static uint32_t next(uint32_t *x) {
  *x ^= *x << 13;
  *x ^= *x >> 17;
  *x ^= *x << 5;
  return *x;
}

/* Random norms, narrow (the 32-bit path) and wide (spans past 2^24 and up to 2^32 - 1), random states. */
static void test_obs_quantize_MatchesTheReferenceOverRandomNormsAndStates(void) {
  uint32_t x = 2463534242u;
  for (unsigned i = 0; i < 4000u; ++i) {
    const unsigned shift = next(&x) % 32u; /* spans from a few µrad to the whole int32 range */
    const int32_t lo = (int32_t)next(&x) >> (shift / 2u);
    int64_t hi = (int64_t)lo + 1 + (int64_t)(next(&x) >> shift);
    hi = hi > INT32_MAX ? INT32_MAX : hi;
    if (hi <= lo) {
      continue;
    }
    norm.theta_min_urad = lo;
    norm.theta_max_urad = (int32_t)hi;
    norm.omega_max_urad_s = (int32_t)(1u + (next(&x) >> (1u + shift % 31u)));
    const int32_t theta = (int32_t)next(&x) >> (next(&x) % 32u);
    const int32_t omega = (int32_t)next(&x) >> (next(&x) % 32u);
    state.theta_urad = theta;
    state.omega_urad_s = omega;
    pour_obs_quantize(&norm, &state, &obs);
    TEST_ASSERT_EQUAL_INT16(reference_q15((int64_t)theta - lo, hi - lo), obs.x[0]);
    TEST_ASSERT_EQUAL_INT16(reference_q15((int64_t)omega + norm.omega_max_urad_s, 2 * (int64_t)norm.omega_max_urad_s),
                            obs.x[1]);
  }
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_obs_quantize_ThetaEndsMapToZeroAndMax);
  RUN_TEST(test_obs_quantize_ThetaSaturatesNeverWraps);
  RUN_TEST(test_obs_quantize_RoundsHalfAnLsbUp);
  RUN_TEST(test_obs_quantize_NegativeThetaMinShiftsTheRange);
  RUN_TEST(test_obs_quantize_WidestNormDoesNotOverflow);
  RUN_TEST(test_obs_quantize_OmegaIsCentredAndSaturates);
  RUN_TEST(test_obs_quantize_NegativeVolumesBecomeZero);
  RUN_TEST(test_obs_norm_validate_RefusesEmptyOrInvertedRanges);
  RUN_TEST(test_obs_quantize_MatchesTheReferenceOverRandomNormsAndStates);
  return UNITY_END();
}
