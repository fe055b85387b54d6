/* SPDX-License-Identifier: MIT */
#include <string.h>

#include "pour/policy.h"
#include "pour/weights_compiled.h"
#include "unity.h"

static int16_t w[POUR_POLICY_N_FEATURES * POUR_POLICY_MAX_ACTIONS];
static q15_t levels[POUR_POLICY_MAX_ACTIONS];
static pour_policy_weights_t weights;
static pour_obs_t obs;
static pour_policy_t policy;
static pour_policy_eval_t ev;

/* A valid policy of n actions with all weights set to value; the hash is recomputed. */
static void make_weights(unsigned n, uint8_t frac_bits, int16_t value) {
  for (unsigned i = 0; i < POUR_POLICY_N_FEATURES * n; ++i) {
    w[i] = value;
  }
  for (unsigned a = 0; a < n; ++a) {
    levels[a] = (q15_t)(-32768 + (int32_t)((65535u * a) / (n - 1u)));
  }
  weights.n_actions = (uint8_t)n;
  weights.w_frac_bits = frac_bits;
  weights.decision_period_ms = 10u;
  weights.w = w;
  weights.action_levels = levels;
  weights.norm.theta_min_urad = 0;
  weights.norm.theta_max_urad = 2356194;
  weights.norm.omega_max_urad_s = 4000000;
  weights.tau_max_mnm = 40000;
  weights.content_hash = pour_policy_weights_hash(&weights);
}

static void set_obs(q15_t v) {
  for (unsigned k = 0; k < POUR_OBS_N; ++k) {
    obs.x[k] = v;
  }
}

static int32_t sum_probs(const q15_t *p, unsigned n) {
  int32_t s = 0;
  for (unsigned a = 0; a < n; ++a) {
    s += p[a];
  }
  return s;
}

void setUp(void) {
  make_weights(11, 11, 0);
  set_obs(0);
  memset(&ev, 0xA5, sizeof ev);
}

void tearDown(void) {}

static void test_policy_logits_AllMaxInputsWithMinWeightsSaturateLow(void) {
  make_weights(2, 0, INT16_MIN);
  set_obs(POUR_Q15_MAX);
  int32_t logits[2];
  pour_policy_logits(&weights, &obs, logits); /* -32768 * (5 * 32767 + 32768) ~ -6.4e9 < INT32_MIN */
  TEST_ASSERT_EQUAL_INT32(INT32_MIN, logits[0]);
  TEST_ASSERT_EQUAL_INT32(INT32_MIN, logits[1]);
}

static void test_policy_logits_AllMaxInputsWithMaxWeightsSaturateHigh(void) {
  make_weights(2, 0, INT16_MAX);
  set_obs(POUR_Q15_MAX);
  int32_t logits[2];
  pour_policy_logits(&weights, &obs, logits);
  TEST_ASSERT_EQUAL_INT32(INT32_MAX, logits[0]);
}

static void test_policy_logits_AccumulatorHoldsTheExtremeExactly(void) {
  /* With 15 fraction bits the extreme sum fits int32 after the shift: it must come out exact, which
   * only an int64 accumulator achieves (the sum itself is ~ -6.4e9). */
  make_weights(2, 15, INT16_MIN);
  set_obs(POUR_Q15_MAX);
  int32_t logits[2];
  pour_policy_logits(&weights, &obs, logits);
  TEST_ASSERT_EQUAL_INT32(-(5 * 32767 + 32768), logits[0]);
  make_weights(2, 15, INT16_MAX);
  pour_policy_logits(&weights, &obs, logits);
  /* 32767 * (5 * 32767 + 32768) / 32768 = 196603 - 5.99997 -> 196597 */
  TEST_ASSERT_EQUAL_INT32(196597, logits[1]);
}

static void test_policy_logits_BiasRowIsExactlyOne(void) {
  make_weights(2, 11, 0);
  w[5 * 2 + 0] = 2048; /* bias weight 1.0 in Q4.11 */
  w[5 * 2 + 1] = -1024; /* -0.5 */
  weights.content_hash = pour_policy_weights_hash(&weights);
  int32_t logits[2];
  pour_policy_logits(&weights, &obs, logits);
  TEST_ASSERT_EQUAL_INT32(32768, logits[0]);
  TEST_ASSERT_EQUAL_INT32(-16384, logits[1]);
}

static void test_policy_logits_RoundsHalfUp(void) {
  make_weights(2, 1, 0);
  obs.x[0] = 1;
  w[0] = 1;  /* 1 * 1 / 2 = 0.5 -> 1 */
  w[1] = -1; /* -0.5 -> 0 (half up) */
  int32_t logits[2];
  pour_policy_logits(&weights, &obs, logits);
  TEST_ASSERT_EQUAL_INT32(1, logits[0]);
  TEST_ASSERT_EQUAL_INT32(0, logits[1]);
  obs.x[0] = 3; /* 1.5 -> 2, -1.5 -> -1 */
  pour_policy_logits(&weights, &obs, logits);
  TEST_ASSERT_EQUAL_INT32(2, logits[0]);
  TEST_ASSERT_EQUAL_INT32(-1, logits[1]);
}

static void test_policy_softmax_EqualLogitsShareEvenly(void) {
  const int32_t logits[16] = {0};
  q15_t p[16];
  pour_policy_softmax_q15(logits, 2, p);
  TEST_ASSERT_EQUAL_INT16(16384, p[0]);
  TEST_ASSERT_EQUAL_INT16(16384, p[1]);
  pour_policy_softmax_q15(logits, 11, p);
  for (unsigned a = 0; a < 11; ++a) {
    TEST_ASSERT_EQUAL_INT16(2979, p[a]); /* 32768 / 11 = 2978.9 */
  }
  pour_policy_softmax_q15(logits, 16, p);
  TEST_ASSERT_EQUAL_INT16(2048, p[15]);
}

static void test_policy_softmax_OneDominantActionSaturatesToMax(void) {
  const int32_t logits[3] = {INT32_MIN, INT32_MAX, INT32_MIN};
  q15_t p[3];
  pour_policy_softmax_q15(logits, 3, p);
  TEST_ASSERT_EQUAL_INT16(0, p[0]);
  TEST_ASSERT_EQUAL_INT16(32767, p[1]);
  TEST_ASSERT_EQUAL_INT16(0, p[2]);
}

static void test_policy_softmax_KnownRatio(void) {
  /* logits 0 and -ln 2 (Q16.15: 22713): p = 2/3, 1/3 -> 21845, 10923 within the table's accuracy */
  const int32_t logits[2] = {0, -22713};
  q15_t p[2];
  pour_policy_softmax_q15(logits, 2, p);
  TEST_ASSERT_INT_WITHIN(2, 21845, p[0]);
  TEST_ASSERT_INT_WITHIN(2, 10923, p[1]);
  TEST_ASSERT_GREATER_THAN_INT16(p[1], p[0]);
}

static void test_policy_softmax_SumWithinHalfLsbPerAction(void) {
  /* Stated bound: |sum p - 32768| <= n/2 LSB. Random logits over several scales, every n. */
  uint32_t rng = 12345u;
  for (unsigned n = POUR_POLICY_MIN_ACTIONS; n <= POUR_POLICY_MAX_ACTIONS; ++n) {
    for (unsigned trial = 0; trial < 300u; ++trial) {
      int32_t logits[POUR_POLICY_MAX_ACTIONS];
      const unsigned scale = trial % 4u; /* spreads of ~1, ~16, ~256, full int32 */
      for (unsigned a = 0; a < n; ++a) {
        const uint32_t r = pour_policy_xorshift32(&rng);
        logits[a] = scale == 3u ? (int32_t)r : (int32_t)(r >> (16u - 4u * scale)) - (int32_t)(1u << (15u + 4u * scale));
      }
      q15_t p[POUR_POLICY_MAX_ACTIONS];
      pour_policy_softmax_q15(logits, n, p);
      const int32_t err = sum_probs(p, n) - 32768;
      TEST_ASSERT_TRUE_MESSAGE(2 * (err < 0 ? -err : err) <= (int32_t)n, "|sum p - 1| > n/2 LSB");
      for (unsigned a = 0; a < n; ++a) {
        TEST_ASSERT_TRUE(p[a] >= 0);
      }
    }
  }
}

static void test_policy_softmax_LargerLogitNeverGetsLessMass(void) {
  const int32_t logits[4] = {100000, 50000, 50001, -7};
  q15_t p[4];
  pour_policy_softmax_q15(logits, 4, p);
  TEST_ASSERT_TRUE(p[0] >= p[2]);
  TEST_ASSERT_TRUE(p[2] >= p[1]);
  TEST_ASSERT_TRUE(p[1] >= p[3]);
}

static void test_policy_argmax_PicksIndexZeroWhenItIsTheMax(void) {
  const int32_t logits[5] = {10, 9, -3, 9, 0};
  TEST_ASSERT_EQUAL_UINT(0u, pour_policy_argmax(logits, 5));
}

static void test_policy_argmax_PicksLowestIndexOnTie(void) {
  const int32_t logits[5] = {1, 7, 3, 7, 7};
  TEST_ASSERT_EQUAL_UINT(1u, pour_policy_argmax(logits, 5));
  const int32_t flat[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  TEST_ASSERT_EQUAL_UINT(0u, pour_policy_argmax(flat, 3));
}

static void test_policy_argmax_PicksTheLastIndex(void) {
  const int32_t logits[16] = {[15] = 1};
  TEST_ASSERT_EQUAL_UINT(15u, pour_policy_argmax(logits, 16));
}

static void test_policy_xorshift32_MatchesReferenceSequence(void) {
  uint32_t s = 1u;
  TEST_ASSERT_EQUAL_HEX32(0x00042021u, pour_policy_xorshift32(&s));
  TEST_ASSERT_EQUAL_HEX32(0x04080601u, pour_policy_xorshift32(&s));
  s = 2463534242u;
  TEST_ASSERT_EQUAL_HEX32(723471715u, pour_policy_xorshift32(&s));
}

static void test_policy_sample_NeverPicksZeroProbability(void) {
  const q15_t p[4] = {0, 20000, 0, 12768};
  uint32_t rng = 99u;
  unsigned counts[4] = {0};
  for (unsigned i = 0; i < 2000u; ++i) {
    counts[pour_policy_sample(p, 4, &rng)]++;
  }
  TEST_ASSERT_EQUAL_UINT(0u, counts[0]);
  TEST_ASSERT_EQUAL_UINT(0u, counts[2]);
  /* 20000/32768 = 0.61: 1221 expected of 2000; 5 sigma ~ 110 */
  TEST_ASSERT_UINT_WITHIN(110u, 1221u, counts[1]);
}

static void test_policy_init_RefusesBadArguments(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_init(NULL, &weights, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_init(&policy, NULL, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_policy_init(&policy, &weights, (pour_policy_mode_t)7, 1u));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &weights, POUR_POLICY_SAMPLED, 0u));
  TEST_ASSERT_NOT_EQUAL(0u, policy.rng); /* seed 0 replaced: xorshift32 would stick at 0 */
}

static void test_policy_eval_GreedyFollowsArgmaxAndClearsUnusedSlots(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  set_obs(0);
  obs.x[1] = 16384; /* upright, still, full rotating bucket: the example policy tilts forward */
  obs.x[2] = 32767;
  pour_policy_eval(&policy, &obs, &ev);
  const unsigned n = pour_weights_compiled.n_actions;
  TEST_ASSERT_EQUAL_UINT8(pour_policy_argmax(ev.logits, n), ev.action);
  TEST_ASSERT_TRUE(pour_weights_compiled.action_levels[ev.action] > 0);
  for (unsigned a = n; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    TEST_ASSERT_EQUAL_INT32(0, ev.logits[a]);
    TEST_ASSERT_EQUAL_INT16(0, ev.probs[a]);
  }
}

static void test_policy_eval_ExampleTurnsBackOncePoured(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  set_obs(0);
  obs.x[0] = 27853; /* tilted ~115 deg, still, poured: the target holds the liquid */
  obs.x[1] = 16384;
  obs.x[2] = 0;
  obs.x[3] = 32767;
  pour_policy_eval(&policy, &obs, &ev);
  TEST_ASSERT_TRUE(pour_weights_compiled.action_levels[ev.action] < 0);
}

static void test_policy_eval_SampledIsReproducibleFromTheSeed(void) {
  pour_policy_t a;
  pour_policy_t b;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&a, &pour_weights_compiled, POUR_POLICY_SAMPLED, 42u));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&b, &pour_weights_compiled, POUR_POLICY_SAMPLED, 42u));
  set_obs(8000);
  pour_policy_eval_t eb;
  unsigned differs = 0;
  uint8_t first = 0;
  for (unsigned i = 0; i < 200u; ++i) {
    pour_policy_eval(&a, &obs, &ev);
    pour_policy_eval(&b, &obs, &eb);
    TEST_ASSERT_EQUAL_UINT8(ev.action, eb.action);
    if (i == 0u) {
      first = ev.action;
    }
    differs += ev.action != first;
  }
  TEST_ASSERT_TRUE_MESSAGE(differs > 0u, "sampled mode always picked the same action");
}

/* pour_policy_decide's kernel (int32 sums, two actions at a time, the DSP path on the Cortex-M4) against
 * pour_policy_logits (the int64-exact general one): random weights scaled so that some policies fit int32 and
 * some do not, every n (odd and even), every f, random and extreme observations. */
static void test_policy_decide_LogitsEqualTheGeneralKernel(void) {
  uint32_t rng = 12345u;
  unsigned fits = 0, falls_back = 0;
  for (unsigned trial = 0; trial < 600u; ++trial) {
    const unsigned n = POUR_POLICY_MIN_ACTIONS + trial % (POUR_POLICY_MAX_ACTIONS - POUR_POLICY_MIN_ACTIONS + 1u);
    const uint8_t f = (uint8_t)(trial % 16u);
    const unsigned shift = trial % 2u == 0u ? 1u : 2u + pour_policy_xorshift32(&rng) % 14u; /* |w| < 2^15 >> (shift - 1) */
    make_weights(n, f, 0);
    for (unsigned i = 0; i < POUR_POLICY_N_FEATURES * n; ++i) {
      w[i] = (int16_t)(((int32_t)(pour_policy_xorshift32(&rng) >> 16) - 32768) >> (shift - 1u));
    }
    weights.content_hash = pour_policy_weights_hash(&weights);
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &weights, POUR_POLICY_GREEDY, 1u));
    fits += policy.sums_fit_i32 ? 1u : 0u;
    falls_back += policy.sums_fit_i32 ? 0u : 1u;
    for (unsigned j = 0; j < 8u; ++j) {
      for (unsigned k = 0; k < POUR_OBS_N; ++k) {
        const uint32_t r = pour_policy_xorshift32(&rng);
        obs.x[k] = (q15_t)(j == 0u ? 0 : (j == 1u ? POUR_Q15_MAX : (j == 2u ? ((r & 1u) ? POUR_Q15_MAX : 0) : (r >> 17))));
      }
      int32_t expect[POUR_POLICY_MAX_ACTIONS];
      pour_policy_logits(&weights, &obs, expect);
      memset(&ev, 0xA5, sizeof ev);
      (void)pour_policy_decide(&policy, &obs, &ev);
      TEST_ASSERT_EQUAL_INT32_ARRAY(expect, ev.logits, n);
      TEST_ASSERT_EQUAL_UINT8(pour_policy_argmax(expect, n), ev.action);
    }
  }
  TEST_ASSERT_TRUE_MESSAGE(fits > 100u && falls_back > 100u, "the trials did not cover both kernels");
}

/* The int32 kernel's bound is tight: action 0's largest sum, 1 (half, f = 1) + 32767 (32767 + 32767 + 4), is
 * exactly INT32_MAX and fits; one more unit of weight does not, and the general kernel takes over. */
static void test_policy_init_Int32BoundIsExact(void) {
  make_weights(2, 1, 0);
  w[0] = 32767; /* observation 0, action 0 (row-major: w[k * n + a]) */
  w[2] = 32767; /* observation 1 */
  w[8] = 4;     /* observation 4 */
  TEST_ASSERT_TRUE(1 + (int64_t)32767 * (32767 + 32767 + 4) == INT32_MAX); /* no 64-bit asserts on the MCU */
  weights.content_hash = pour_policy_weights_hash(&weights);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &weights, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_TRUE(policy.sums_fit_i32);
  set_obs(POUR_Q15_MAX);
  int32_t expect[2];
  pour_policy_logits(&weights, &obs, expect);
  (void)pour_policy_decide(&policy, &obs, &ev);
  TEST_ASSERT_EQUAL_INT32(INT32_MAX >> 1, ev.logits[0]);
  TEST_ASSERT_EQUAL_INT32_ARRAY(expect, ev.logits, 2);
  w[8] = 5;
  weights.content_hash = pour_policy_weights_hash(&weights);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &weights, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_FALSE(policy.sums_fit_i32);
  pour_policy_logits(&weights, &obs, expect);
  (void)pour_policy_decide(&policy, &obs, &ev);
  TEST_ASSERT_EQUAL_INT32_ARRAY(expect, ev.logits, 2);
  /* The low side: 1 - 32768 * 32768 (bias) - 32768 * 32767 - 1 * 32767 = INT32_MIN + 2 fits, -2 does not. */
  w[8] = 0;
  w[2] = 0;
  w[0] = -32768;
  w[10] = -32768;
  w[4] = -1;
  TEST_ASSERT_TRUE(1 - (int64_t)32768 * 32768 - (int64_t)32767 * (32768 + 1) == (int64_t)INT32_MIN + 2);
  weights.content_hash = pour_policy_weights_hash(&weights);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &weights, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_TRUE(policy.sums_fit_i32);
  pour_policy_logits(&weights, &obs, expect);
  (void)pour_policy_decide(&policy, &obs, &ev);
  TEST_ASSERT_EQUAL_INT32_ARRAY(expect, ev.logits, 2);
  w[4] = -2;
  weights.content_hash = pour_policy_weights_hash(&weights);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &weights, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_FALSE(policy.sums_fit_i32);
}

static void test_policy_init_ShippedPolicyTakesTheInt32Kernel(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  TEST_ASSERT_TRUE(policy.sums_fit_i32);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_policy_logits_AllMaxInputsWithMinWeightsSaturateLow);
  RUN_TEST(test_policy_logits_AllMaxInputsWithMaxWeightsSaturateHigh);
  RUN_TEST(test_policy_logits_AccumulatorHoldsTheExtremeExactly);
  RUN_TEST(test_policy_logits_BiasRowIsExactlyOne);
  RUN_TEST(test_policy_logits_RoundsHalfUp);
  RUN_TEST(test_policy_softmax_EqualLogitsShareEvenly);
  RUN_TEST(test_policy_softmax_OneDominantActionSaturatesToMax);
  RUN_TEST(test_policy_softmax_KnownRatio);
  RUN_TEST(test_policy_softmax_SumWithinHalfLsbPerAction);
  RUN_TEST(test_policy_softmax_LargerLogitNeverGetsLessMass);
  RUN_TEST(test_policy_argmax_PicksIndexZeroWhenItIsTheMax);
  RUN_TEST(test_policy_argmax_PicksLowestIndexOnTie);
  RUN_TEST(test_policy_argmax_PicksTheLastIndex);
  RUN_TEST(test_policy_xorshift32_MatchesReferenceSequence);
  RUN_TEST(test_policy_sample_NeverPicksZeroProbability);
  RUN_TEST(test_policy_init_RefusesBadArguments);
  RUN_TEST(test_policy_eval_GreedyFollowsArgmaxAndClearsUnusedSlots);
  RUN_TEST(test_policy_eval_ExampleTurnsBackOncePoured);
  RUN_TEST(test_policy_eval_SampledIsReproducibleFromTheSeed);
  RUN_TEST(test_policy_decide_LogitsEqualTheGeneralKernel);
  RUN_TEST(test_policy_init_Int32BoundIsExact);
  RUN_TEST(test_policy_init_ShippedPolicyTakesTheInt32Kernel);
  return UNITY_END();
}
