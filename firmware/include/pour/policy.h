/* SPDX-License-Identifier: MIT */
/* Softmax-linear policy in fixed point: logits = [x, 1]·W, greedy argmax or seeded sampling. */
#ifndef POUR_POLICY_H
#define POUR_POLICY_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"
#include "pour/obs.h"

#define POUR_POLICY_N_FEATURES (POUR_OBS_N + 1) /* the five observations, then a bias of exactly 1.0 */
#define POUR_POLICY_MIN_ACTIONS 2
#define POUR_POLICY_MAX_ACTIONS 16
#define POUR_WEIGHTS_FORMAT_VERSION 1

/* A policy as weights.h describes it (docs/weights-h.md). Arrays are borrowed, not copied. */
typedef struct {
  uint8_t n_actions;            /* 2 .. 16 */
  uint8_t w_frac_bits;          /* weights are int16 with this many fraction bits, 0 .. 15 */
  uint16_t decision_period_ms;  /* a new action every this many 1 ms ticks, >= 1 */
  const int16_t *w;             /* [POUR_POLICY_N_FEATURES][n_actions], row-major, Q(15-f).f */
  const q15_t *action_levels;   /* [n_actions] torque as a fraction of tau_max, Q15 */
  pour_obs_norm_t norm;         /* observation normalisation the policy was trained with */
  int32_t tau_max_mnm;          /* tau_max the policy was trained with [mN·m], metadata */
  uint32_t content_hash;        /* FNV-1a 32 of the content (docs/weights-h.md) */
} pour_policy_weights_t;

typedef enum {
  POUR_POLICY_GREEDY = 0, /* argmax of the logits, ties to the lowest index */
  POUR_POLICY_SAMPLED = 1 /* sample from the fixed-point softmax with a seeded xorshift32 */
} pour_policy_mode_t;

typedef struct {
  const pour_policy_weights_t *weights;
  pour_policy_mode_t mode;
  uint32_t rng; /* xorshift32 state, never 0 */
  bool sums_fit_i32; /* every partial sum of the logits fits int32 for any observation: the cheap kernel */
  int32_t half;      /* the logits' rounding: 2^(w_frac_bits - 1), 0 for w_frac_bits 0 */
  /* The weights again, per action, two int16 to a word: {w0 | w1 << 16, w2 | w3 << 16, w4 | bias << 16}, so that
   * the cheap kernel loads an action's six in three words (a copy made by pour_policy_init, 192 B). */
  uint32_t packed[POUR_POLICY_MAX_ACTIONS][3];
} pour_policy_t;

/* One evaluation: logits Q16.15 in int32, probabilities Q15 (sum within docs' LSB bound of 1). */
typedef struct {
  int32_t logits[POUR_POLICY_MAX_ACTIONS];
  q15_t probs[POUR_POLICY_MAX_ACTIONS];
  uint8_t action;
} pour_policy_eval_t;

/* FNV-1a 32 content hash of weights, as docs/weights-h.md defines it. */
uint32_t pour_policy_weights_hash(const pour_policy_weights_t *weights);

/* Checks shape, formats, levels, normalisation and the content hash. */
pour_status_t pour_policy_weights_validate(const pour_policy_weights_t *weights);

/* Validates the weights and binds them; seed 0 is replaced by a fixed non-zero seed. */
pour_status_t pour_policy_init(pour_policy_t *policy, const pour_policy_weights_t *weights,
                               pour_policy_mode_t mode, uint32_t seed);

/* Evaluates the policy on one observation (elements in [0, 32767], as pour_obs_quantize makes them).
 * Never fails on an initialised policy. Equals pour_policy_decide, then pour_policy_fill_probs if needed. */
void pour_policy_eval(pour_policy_t *policy, const pour_obs_t *obs, pour_policy_eval_t *out);

/* The decision alone: the n_actions logits and the action (out->logits past n_actions are left as they were:
 * pour_policy_eval zeroes them). Greedy mode needs no probabilities for it and leaves out->probs as they were
 * (returns false); sampled mode draws from them, so fills them (returns true). */
bool pour_policy_decide(pour_policy_t *policy, const pour_obs_t *obs, pour_policy_eval_t *out);

/* The probabilities of out->logits (softmax, zero past n_actions): what a greedy decision left out. */
void pour_policy_fill_probs(const pour_policy_t *policy, pour_policy_eval_t *out);

/* The kernels pour_policy_eval is made of, exposed for tests and the benchmark. */

/* logits[a] = round((x·W)[a] / 2^f), x = [obs Q15 in [0, 32767], 1.0], W Q(15-f).f, int64 accumulator;
 * Q16.15, rounded half up, saturated to int32. logits has weights->n_actions entries. */
void pour_policy_logits(const pour_policy_weights_t *weights, const pour_obs_t *obs, int32_t *logits);

/* Softmax of n (1..16) Q16.15 logits into Q15 probabilities: max subtracted, exp in Q16 by table and
 * linear interpolation, p = round(32768 e / sum e) saturated to 32767; |sum p - 32768| <= n/2 LSB. */
void pour_policy_softmax_q15(const int32_t *logits, unsigned n, q15_t *probs);

/* Index of the largest of n logits; ties go to the lowest index. */
unsigned pour_policy_argmax(const int32_t *logits, unsigned n);

/* Marsaglia's xorshift32 (13, 17, 5): advances *state (non-zero) and returns the new value. */
uint32_t pour_policy_xorshift32(uint32_t *state);

/* Draws an action from n Q15 probabilities: u = (xorshift32 * sum p) >> 32, first a with u < cum p. */
unsigned pour_policy_sample(const q15_t *probs, unsigned n, uint32_t *rng);

#endif /* POUR_POLICY_H */
