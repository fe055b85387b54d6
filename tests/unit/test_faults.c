/* SPDX-License-Identifier: MIT */
#include <string.h>

#include "pour/faults.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_faults_name_NamesEveryBitOfTheMaskOnce(void) {
  uint16_t named = 0u;
  for (unsigned i = 0; i < 16u; ++i) {
    const uint16_t bit = (uint16_t)(1u << i);
    const char *name = pour_fault_name(bit);
    TEST_ASSERT_EQUAL((bit & POUR_FAULT_ALL) != 0u, name != NULL);
    if (name != NULL) {
      named |= bit;
      for (unsigned j = 0; j < i; ++j) {
        const char *other = pour_fault_name((uint16_t)(1u << j));
        TEST_ASSERT_TRUE(other == NULL || strcmp(name, other) != 0);
      }
    }
  }
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_ALL, named);
  TEST_ASSERT_EQUAL_HEX16((1u << POUR_FAULT_COUNT) - 1u, POUR_FAULT_ALL);
}

static void test_faults_name_SpellsTheMacros(void) {
  TEST_ASSERT_EQUAL_STRING("STALE_INPUT", pour_fault_name(POUR_FAULT_STALE_INPUT));
  TEST_ASSERT_EQUAL_STRING("LINK", pour_fault_name(POUR_FAULT_LINK));
  TEST_ASSERT_EQUAL_STRING("SCALE", pour_fault_name(POUR_FAULT_SCALE));
}

static void test_faults_name_RefusesZeroAndSeveralBits(void) {
  TEST_ASSERT_NULL(pour_fault_name(0u));
  TEST_ASSERT_NULL(pour_fault_name(POUR_FAULT_ESTOP | POUR_FAULT_LINK));
  TEST_ASSERT_NULL(pour_fault_name(0x8000u));
}

static void test_faults_mode_name_NamesEachMode(void) {
  TEST_ASSERT_EQUAL_STRING("IDLE", pour_mode_name(POUR_MODE_IDLE));
  TEST_ASSERT_EQUAL_STRING("RUN", pour_mode_name(POUR_MODE_RUN));
  TEST_ASSERT_EQUAL_STRING("FAULT", pour_mode_name(POUR_MODE_FAULT));
  TEST_ASSERT_EQUAL_STRING("ESTOP", pour_mode_name(POUR_MODE_ESTOP));
  TEST_ASSERT_NULL(pour_mode_name(POUR_MODE_COUNT));
  TEST_ASSERT_NULL(pour_mode_name(255u));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_faults_name_NamesEveryBitOfTheMaskOnce);
  RUN_TEST(test_faults_name_SpellsTheMacros);
  RUN_TEST(test_faults_name_RefusesZeroAndSeveralBits);
  RUN_TEST(test_faults_mode_name_NamesEachMode);
  return UNITY_END();
}
