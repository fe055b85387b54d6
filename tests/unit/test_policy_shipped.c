/* SPDX-License-Identifier: MIT */
/* The shipped policy (policy/weights.h, as the image compiles it): pour_policy_decide's int32 kernel (the DSP
 * path on the Cortex-M4) against pour_policy_logits' int64 kernel, and its action against pour_policy_argmax,
 * over random and extreme observations. */
#include <string.h>

#include "pour/policy.h"
#include "pour/weights_compiled.h"
#include "unity.h"

void setUp(void) {}

void tearDown(void) {}

static void test_policy_shipped_DecisionsEqualTheGeneralKernel(void) {
  pour_policy_t policy;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_TRUE(policy.sums_fit_i32);
  const unsigned n = pour_weights_compiled.n_actions;
  uint32_t x = 2463534242u;
  for (unsigned i = 0; i < 20000u; ++i) {
    pour_obs_t obs;
    for (unsigned k = 0; k < POUR_OBS_N; ++k) {
      x ^= x << 13;
      x ^= x >> 17;
      x ^= x << 5;
      obs.x[k] = (q15_t)((i & 7u) == 0u ? ((x & 1u) ? POUR_Q15_MAX : 0) : (int32_t)(x >> 17));
    }
    int32_t expect[POUR_POLICY_MAX_ACTIONS];
    pour_policy_logits(&pour_weights_compiled, &obs, expect);
    pour_policy_eval_t ev;
    memset(&ev, 0x5A, sizeof ev);
    (void)pour_policy_decide(&policy, &obs, &ev);
    TEST_ASSERT_EQUAL_INT32_ARRAY(expect, ev.logits, n);
    TEST_ASSERT_EQUAL_UINT8(pour_policy_argmax(expect, n), ev.action);
  }
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_policy_shipped_DecisionsEqualTheGeneralKernel);
  return UNITY_END();
}
