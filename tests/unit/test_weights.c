/* SPDX-License-Identifier: MIT */
#include <string.h>

#include "pour/policy.h"
#include "pour/weights_compiled.h"
#include "unity.h"

/* example_weights.h, compiled by weights_compiled.c into pour_weights_compiled for this test. */
static int16_t w[POUR_POLICY_N_FEATURES * POUR_POLICY_MAX_ACTIONS];
static q15_t levels[POUR_POLICY_MAX_ACTIONS];
static pour_policy_weights_t copy;

void setUp(void) {
  copy = pour_weights_compiled;
  memcpy(w, pour_weights_compiled.w, sizeof(int16_t) * POUR_POLICY_N_FEATURES * copy.n_actions);
  memcpy(levels, pour_weights_compiled.action_levels, sizeof(q15_t) * copy.n_actions);
  copy.w = w;
  copy.action_levels = levels;
}

void tearDown(void) {}

static void rehash(void) { copy.content_hash = pour_policy_weights_hash(&copy); }

static void test_weights_hash_MatchesThePythonWriter(void) {
  /* The header's CONTENT_HASH was computed by tools/pour/policy/weights_h.py. */
  TEST_ASSERT_EQUAL_HEX32(pour_weights_compiled.content_hash, pour_policy_weights_hash(&pour_weights_compiled));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_weights_validate(&pour_weights_compiled));
}

static void test_weights_hash_ChangesWithEveryField(void) {
  const uint32_t h0 = pour_policy_weights_hash(&copy);
  copy.decision_period_ms++;
  TEST_ASSERT_NOT_EQUAL(h0, pour_policy_weights_hash(&copy));
  setUp();
  copy.norm.omega_max_urad_s++;
  TEST_ASSERT_NOT_EQUAL(h0, pour_policy_weights_hash(&copy));
  setUp();
  copy.tau_max_mnm++;
  TEST_ASSERT_NOT_EQUAL(h0, pour_policy_weights_hash(&copy));
  setUp();
  levels[3] = (q15_t)(levels[3] + 1);
  TEST_ASSERT_NOT_EQUAL(h0, pour_policy_weights_hash(&copy));
}

static void test_weights_validate_RefusesACorruptedTable(void) {
  w[7] = (int16_t)(w[7] ^ 0x0100);
  TEST_ASSERT_EQUAL_INT(POUR_ECORRUPT, pour_policy_weights_validate(&copy));
  setUp();
  copy.content_hash ^= 1u;
  TEST_ASSERT_EQUAL_INT(POUR_ECORRUPT, pour_policy_weights_validate(&copy));
}

static void test_weights_validate_RefusesBadShapes(void) {
  copy.n_actions = 1u;
  rehash();
  TEST_ASSERT_EQUAL_INT(POUR_ESHAPE, pour_policy_weights_validate(&copy));
  copy.n_actions = 17u;
  TEST_ASSERT_EQUAL_INT(POUR_ESHAPE, pour_policy_weights_validate(&copy));
  copy.n_actions = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_ESHAPE, pour_policy_weights_validate(&copy));
}

static void test_weights_validate_RefusesBadFormats(void) {
  copy.w_frac_bits = 16u;
  rehash();
  TEST_ASSERT_EQUAL_INT(POUR_EFORMAT, pour_policy_weights_validate(&copy));
}

static void test_weights_validate_RefusesBadValues(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(NULL));
  copy.w = NULL;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(&copy));
  setUp();
  copy.action_levels = NULL;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(&copy));
  setUp();
  copy.decision_period_ms = 0u;
  rehash();
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(&copy));
  setUp();
  copy.tau_max_mnm = 0;
  rehash();
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(&copy));
  setUp();
  copy.norm.theta_max_urad = copy.norm.theta_min_urad;
  rehash();
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(&copy));
  setUp();
  levels[4] = levels[3]; /* levels must strictly increase */
  rehash();
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_weights_validate(&copy));
}

static void test_weights_compiled_CarriesTheHeaderFields(void) {
  TEST_ASSERT_EQUAL_UINT8(11u, pour_weights_compiled.n_actions);
  TEST_ASSERT_EQUAL_UINT16(10u, pour_weights_compiled.decision_period_ms);
  TEST_ASSERT_EQUAL_INT16(-32768, pour_weights_compiled.action_levels[0]);
  TEST_ASSERT_EQUAL_INT16(0, pour_weights_compiled.action_levels[5]);
  TEST_ASSERT_EQUAL_INT16(32767, pour_weights_compiled.action_levels[10]);
  TEST_ASSERT_EQUAL_INT32(2356194, pour_weights_compiled.norm.theta_max_urad);
  TEST_ASSERT_EQUAL_INT32(20000, pour_weights_compiled.tau_max_mnm);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_weights_hash_MatchesThePythonWriter);
  RUN_TEST(test_weights_hash_ChangesWithEveryField);
  RUN_TEST(test_weights_validate_RefusesACorruptedTable);
  RUN_TEST(test_weights_validate_RefusesBadShapes);
  RUN_TEST(test_weights_validate_RefusesBadFormats);
  RUN_TEST(test_weights_validate_RefusesBadValues);
  RUN_TEST(test_weights_compiled_CarriesTheHeaderFields);
  return UNITY_END();
}
