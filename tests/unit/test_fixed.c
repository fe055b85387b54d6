/* SPDX-License-Identifier: MIT */
#include "pour/fixed.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_fixed_sat_q15_ClampsAtBothEnds(void) {
  TEST_ASSERT_EQUAL_INT16(32767, pour_sat_q15(32768));
  TEST_ASSERT_EQUAL_INT16(32767, pour_sat_q15(INT32_MAX));
  TEST_ASSERT_EQUAL_INT16(-32768, pour_sat_q15(-32769));
  TEST_ASSERT_EQUAL_INT16(-32768, pour_sat_q15(INT32_MIN));
  TEST_ASSERT_EQUAL_INT16(-32768, pour_sat_q15(-32768));
  TEST_ASSERT_EQUAL_INT16(123, pour_sat_q15(123));
}

static void test_fixed_sat_i32_ClampsAtBothEnds(void) {
  TEST_ASSERT_EQUAL_INT32(INT32_MAX, pour_sat_i32((int64_t)INT32_MAX + 1));
  TEST_ASSERT_EQUAL_INT32(INT32_MIN, pour_sat_i32((int64_t)INT32_MIN - 1));
  TEST_ASSERT_EQUAL_INT32(INT32_MAX, pour_sat_i32(INT64_MAX));
  TEST_ASSERT_EQUAL_INT32(INT32_MIN, pour_sat_i32(INT64_MIN));
  TEST_ASSERT_EQUAL_INT32(-5, pour_sat_i32(-5));
}

static void test_fixed_status_name_NamesEveryStatus(void) {
  TEST_ASSERT_EQUAL_STRING("POUR_OK", pour_status_name(POUR_OK));
  TEST_ASSERT_EQUAL_STRING("POUR_EINVAL", pour_status_name(POUR_EINVAL));
  TEST_ASSERT_EQUAL_STRING("POUR_ESHAPE", pour_status_name(POUR_ESHAPE));
  TEST_ASSERT_EQUAL_STRING("POUR_EFORMAT", pour_status_name(POUR_EFORMAT));
  TEST_ASSERT_EQUAL_STRING("POUR_ECORRUPT", pour_status_name(POUR_ECORRUPT));
  TEST_ASSERT_EQUAL_STRING("POUR_ECALIBRATION", pour_status_name(POUR_ECALIBRATION));
  TEST_ASSERT_EQUAL_STRING("POUR_EBOOT", pour_status_name(POUR_EBOOT));
  TEST_ASSERT_EQUAL_STRING("POUR_EPARAMS", pour_status_name(POUR_EPARAMS));
  TEST_ASSERT_EQUAL_STRING("POUR_EALIGN", pour_status_name(POUR_EALIGN));
  TEST_ASSERT_EQUAL_STRING("POUR_E?", pour_status_name((pour_status_t)-99));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_fixed_sat_q15_ClampsAtBothEnds);
  RUN_TEST(test_fixed_sat_i32_ClampsAtBothEnds);
  RUN_TEST(test_fixed_status_name_NamesEveryStatus);
  return UNITY_END();
}
