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

static void test_faults_format_JoinsTheNamesInBitOrder(void) {
  char buf[POUR_FAULTS_TEXT_MAX];
  TEST_ASSERT_EQUAL_STRING("none", pour_faults_format(0u, buf, sizeof buf));
  TEST_ASSERT_EQUAL_STRING("ESTOP", pour_faults_format(POUR_FAULT_ESTOP, buf, sizeof buf));
  TEST_ASSERT_EQUAL_STRING("STALE_INPUT,SEQ", pour_faults_format(POUR_FAULT_SEQ | POUR_FAULT_STALE_INPUT, buf, sizeof buf));
  TEST_ASSERT_EQUAL_STRING("LINK,BIT12,BIT15", pour_faults_format(POUR_FAULT_LINK | 0x9000u, buf, sizeof buf));
}

static void test_faults_format_EveryBitFitsTheDeclaredSize(void) {
  char buf[POUR_FAULTS_TEXT_MAX + 8u];
  memset(buf, 'x', sizeof buf);
  pour_faults_format(0xFFFFu, buf, sizeof buf);
  TEST_ASSERT_TRUE(strlen(buf) < POUR_FAULTS_TEXT_MAX);
  TEST_ASSERT_EQUAL_STRING_LEN("STALE_INPUT,ESTOP,", buf, 18);
}

static void test_faults_format_CutsShortAndTerminates(void) {
  char buf[8];
  memset(buf, 'x', sizeof buf);
  TEST_ASSERT_EQUAL_STRING("STALE_I", pour_faults_format(POUR_FAULT_STALE_INPUT, buf, sizeof buf));
  char one[1] = {'x'};
  TEST_ASSERT_EQUAL_STRING("", pour_faults_format(POUR_FAULT_ESTOP, one, sizeof one));
  TEST_ASSERT_NULL(pour_faults_format(POUR_FAULT_ESTOP, NULL, 4u));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_faults_name_NamesEveryBitOfTheMaskOnce);
  RUN_TEST(test_faults_name_SpellsTheMacros);
  RUN_TEST(test_faults_name_RefusesZeroAndSeveralBits);
  RUN_TEST(test_faults_mode_name_NamesEachMode);
  RUN_TEST(test_faults_format_JoinsTheNamesInBitOrder);
  RUN_TEST(test_faults_format_EveryBitFitsTheDeclaredSize);
  RUN_TEST(test_faults_format_CutsShortAndTerminates);
  return UNITY_END();
}
