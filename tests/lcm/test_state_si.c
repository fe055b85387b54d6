/* SPDX-License-Identifier: MIT */
/* SI → fixed-point conversion of the plant state (the one both the LCM controller and the in-process
 * loop use): round half away from zero, then saturate; NaN lands outside every valid range. */
#include <math.h>

#include "state_si.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_state_si_UradRoundsHalfAwayFromZero(void) {
  TEST_ASSERT_EQUAL_INT32(0, pour_si_to_urad(0.0));
  TEST_ASSERT_EQUAL_INT32(1, pour_si_to_urad(0.5e-6));
  TEST_ASSERT_EQUAL_INT32(-1, pour_si_to_urad(-0.5e-6));
  TEST_ASSERT_EQUAL_INT32(0, pour_si_to_urad(0.49e-6));
  TEST_ASSERT_EQUAL_INT32(2356194, pour_si_to_urad(2.356194490192345));
  TEST_ASSERT_EQUAL_INT32(-1570796, pour_si_to_urad(-1.5707963267948966));
}

static void test_state_si_UradSaturatesAndNanIsOutOfRange(void) {
  TEST_ASSERT_EQUAL_INT32(INT32_MAX, pour_si_to_urad(3000.0));
  TEST_ASSERT_EQUAL_INT32(INT32_MIN, pour_si_to_urad(-3000.0));
  TEST_ASSERT_EQUAL_INT32(INT32_MAX, pour_si_to_urad(INFINITY));
  TEST_ASSERT_EQUAL_INT32(INT32_MIN, pour_si_to_urad(-INFINITY));
  TEST_ASSERT_EQUAL_INT32(INT32_MAX, pour_si_to_urad(NAN));
}

static void test_state_si_Q15EdgeValues(void) {
  TEST_ASSERT_EQUAL_INT16(32767, pour_si_to_q15(1.0));
  TEST_ASSERT_EQUAL_INT16(32767, pour_si_to_q15(2.0));
  TEST_ASSERT_EQUAL_INT16(0, pour_si_to_q15(-1.0)); /* a volume is never negative */
  TEST_ASSERT_EQUAL_INT16(0, pour_si_to_q15(0.0));
  TEST_ASSERT_EQUAL_INT16(0, pour_si_to_q15(0.5 / 32768.0)); /* half an LSB: ties to even */
  TEST_ASSERT_EQUAL_INT16(2, pour_si_to_q15(1.5 / 32768.0));
  TEST_ASSERT_EQUAL_INT16(1, pour_si_to_q15(0.6 / 32768.0));
  TEST_ASSERT_EQUAL_INT16(16384, pour_si_to_q15(0.5));
  TEST_ASSERT_EQUAL_INT16(32766, pour_si_to_q15(32766.5 / 32768.0)); /* tie to even, inside */
  TEST_ASSERT_EQUAL_INT16(-32768, pour_si_to_q15(NAN));
}

static void test_state_si_StateFromSiFillsEveryField(void) {
  pour_state_t s;
  pour_state_from_si(&s, 0x100000005LL, 0.25, -2.0, 0.75, 0.125, 0.0);
  TEST_ASSERT_EQUAL_UINT32(5u, s.seq); /* the low 32 bits */
  TEST_ASSERT_EQUAL_INT32(250000, s.theta_urad);
  TEST_ASSERT_EQUAL_INT32(-2000000, s.omega_urad_s);
  TEST_ASSERT_EQUAL_INT16(24576, s.v_rotating);
  TEST_ASSERT_EQUAL_INT16(4096, s.v_target);
  TEST_ASSERT_EQUAL_INT16(0, s.v_spill);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_state_si_UradRoundsHalfAwayFromZero);
  RUN_TEST(test_state_si_UradSaturatesAndNanIsOutOfRange);
  RUN_TEST(test_state_si_Q15EdgeValues);
  RUN_TEST(test_state_si_StateFromSiFillsEveryField);
  return UNITY_END();
}
