/* SPDX-License-Identifier: MIT */
#include "pour/foc.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_foc_sincos_HitsTheAxesExactly(void) {
  q15_t s, c;
  pour_foc_sincos_q15(0, &s, &c);
  TEST_ASSERT_EQUAL_INT16(0, s);
  TEST_ASSERT_EQUAL_INT16(32767, c);
  pour_foc_sincos_q15(16384, &s, &c);
  TEST_ASSERT_EQUAL_INT16(32767, s);
  TEST_ASSERT_EQUAL_INT16(0, c);
  pour_foc_sincos_q15(32768, &s, &c);
  TEST_ASSERT_EQUAL_INT16(0, s);
  TEST_ASSERT_EQUAL_INT16(-32767, c);
  pour_foc_sincos_q15(49152, &s, &c);
  TEST_ASSERT_EQUAL_INT16(-32767, s);
}

static void test_foc_sincos_ThirtyDegreesIsOneHalf(void) {
  q15_t s, c;
  pour_foc_sincos_q15(5461, &s, &c); /* 5461.33 LSB = 30° */
  TEST_ASSERT_INT_WITHIN(2, 16383, s); /* sin(29.9994°) = 0.499991 → 16383.7 */
  TEST_ASSERT_INT_WITHIN(2, 28378, c);
}

static void test_foc_sincos_UnitCircleAtEveryAngle(void) {
  /* s² + c² within 2 LSB of 1.0 (the rounding of each), and sin odd: sin(−a) = −sin(a) */
  for (uint32_t a = 0; a < 65536u; a += 7u) {
    q15_t s, c, s2, c2;
    pour_foc_sincos_q15((uint16_t)a, &s, &c);
    const int32_t r2 = (int32_t)s * s + (int32_t)c * c;
    TEST_ASSERT_INT_WITHIN(2 * 2 * 32768, 1 << 30, r2);
    pour_foc_sincos_q15((uint16_t)(65536u - a), &s2, &c2);
    TEST_ASSERT_EQUAL_INT16(-s, s2);
    TEST_ASSERT_EQUAL_INT16(c, c2);
  }
}

static void test_foc_sincos_RisesMonotonicallyOverTheFirstQuadrant(void) {
  q15_t prev = -1, s, c;
  for (uint32_t a = 0; a <= 16384u; ++a) {
    pour_foc_sincos_q15((uint16_t)a, &s, &c);
    TEST_ASSERT_TRUE(s >= prev);
    prev = s;
  }
}

static void test_foc_clarke_BalancedCurrentsMapToAlphaBeta(void) {
  q15_t a, b;
  pour_foc_clarke_q15(1000, -500, -500, &a, &b);
  TEST_ASSERT_EQUAL_INT16(1000, a);
  TEST_ASSERT_EQUAL_INT16(0, b);
  pour_foc_clarke_q15(0, 866, -866, &a, &b);
  TEST_ASSERT_EQUAL_INT16(0, a);
  TEST_ASSERT_INT_WITHIN(1, 1000, b);
  pour_foc_clarke_q15(32767, -32768, -32768, &a, &b); /* saturates, does not wrap */
  TEST_ASSERT_EQUAL_INT16(32767, a);
}

static void test_foc_park_RoundTripsThroughInversePark(void) {
  for (uint32_t a = 0; a < 65536u; a += 997u) {
    q15_t s, c, al, be, d, q;
    pour_foc_sincos_q15((uint16_t)a, &s, &c);
    pour_foc_inv_park_q15(-3000, 12000, s, c, &al, &be);
    pour_foc_park_q15(al, be, s, c, &d, &q);
    TEST_ASSERT_INT_WITHIN(2, -3000, d);
    TEST_ASSERT_INT_WITHIN(2, 12000, q);
  }
}

static const pour_foc_modulation_t mod = {500, 256, 31130};

static void test_foc_modulate_ZeroVoltageIsHalfDuty(void) {
  const q15_t i[3] = {0, 0, 0};
  int32_t d[3];
  pour_foc_modulate_q15(0, 0, 12288, i, &mod, d);
  for (int k = 0; k < 3; ++k) TEST_ASSERT_EQUAL_INT32(16384, d[k]);
}

static void test_foc_modulate_LineVoltagesFollowTheVector(void) {
  /* α = vbus/2 along phase a: a − b = 1.5·α/vbus of duty = 0.75 */
  const q15_t i[3] = {0, 0, 0};
  int32_t d[3];
  pour_foc_modulate_q15(6144, 0, 12288, i, &mod, d);
  TEST_ASSERT_INT_WITHIN(2, 24576, d[0] - d[1]);
  TEST_ASSERT_EQUAL_INT32(d[1], d[2]);
  TEST_ASSERT_INT_WITHIN(2, 16384, (d[0] + d[1]) / 2); /* centred by the injection */
}

static void test_foc_modulate_DeadTimeCompensationFollowsTheCurrent(void) {
  const q15_t i[3] = {5000, -5000, 100}; /* 100: inside the band, compensated in proportion */
  int32_t d[3];
  pour_foc_modulate_q15(0, 0, 12288, i, &mod, d);
  TEST_ASSERT_EQUAL_INT32(16384 + 500, d[0]);
  TEST_ASSERT_EQUAL_INT32(16384 - 500, d[1]);
  TEST_ASSERT_EQUAL_INT32(16384 + 500 * 100 / 256, d[2]);
}

static void test_foc_modulate_NeverLeavesTheDutyRange(void) {
  const q15_t vb[] = {-32768, -1, 0, 1, 100, 32767};
  const q15_t v[] = {-32768, -12000, 0, 12000, 32767};
  const q15_t i[3] = {32767, -32768, 0};
  for (unsigned b = 0; b < sizeof vb / sizeof vb[0]; ++b)
    for (unsigned x = 0; x < sizeof v / sizeof v[0]; ++x)
      for (unsigned y = 0; y < sizeof v / sizeof v[0]; ++y) {
        int32_t d[3];
        pour_foc_modulate_q15(v[x], v[y], vb[b], i, &mod, d);
        for (int k = 0; k < 3; ++k) TEST_ASSERT_TRUE(d[k] >= 0 && d[k] <= mod.duty_max_q15);
      }
}

static void test_foc_isqrt_IsTheFloorOfTheRoot(void) {
  const uint32_t xs[] = {0u, 1u, 2u, 3u, 4u, 15u, 16u, 17u, 1000000u, 1073741823u, 1073741824u, 4294967295u};
  for (unsigned k = 0; k < sizeof xs / sizeof xs[0]; ++k) {
    const uint64_t r = pour_foc_isqrt_u32(xs[k]);
    TEST_ASSERT_TRUE(r * r <= xs[k]);
    TEST_ASSERT_TRUE((r + 1) * (r + 1) > xs[k]);
  }
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_foc_sincos_HitsTheAxesExactly);
  RUN_TEST(test_foc_sincos_ThirtyDegreesIsOneHalf);
  RUN_TEST(test_foc_sincos_UnitCircleAtEveryAngle);
  RUN_TEST(test_foc_sincos_RisesMonotonicallyOverTheFirstQuadrant);
  RUN_TEST(test_foc_clarke_BalancedCurrentsMapToAlphaBeta);
  RUN_TEST(test_foc_park_RoundTripsThroughInversePark);
  RUN_TEST(test_foc_modulate_ZeroVoltageIsHalfDuty);
  RUN_TEST(test_foc_modulate_LineVoltagesFollowTheVector);
  RUN_TEST(test_foc_modulate_DeadTimeCompensationFollowsTheCurrent);
  RUN_TEST(test_foc_modulate_NeverLeavesTheDutyRange);
  RUN_TEST(test_foc_isqrt_IsTheFloorOfTheRoot);
  return UNITY_END();
}
