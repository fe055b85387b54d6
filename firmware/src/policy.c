/* SPDX-License-Identifier: MIT */
#include "pour/policy.h"

#include <stddef.h>
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP
#include <arm_acle.h>
#include <string.h>
#endif

/* Rounding right shifts below rely on >> of a negative int64 being arithmetic (floor), as GCC and
 * Clang define it and as Python's >> behaves. */
_Static_assert((-3 >> 1) == -2, "arithmetic right shift required");

#define FNV_OFFSET_BASIS 2166136261u
#define FNV_PRIME 16777619u
#define DEFAULT_SEED 2463534242u

/* 2^(-j/64) in Q24 for j = 0..64: round(2^(-j/64) * 2^24), regenerated and checked by
 * tools/pour/policy/fixedpoint.py (EXP2_TABLE_Q24). */
static const uint32_t exp2_neg_q24[65] = {
    16777216u, 16596492u, 16417715u, 16240863u, 16065917u, 15892855u, 15721658u, 15552304u,
    15384775u, 15219050u, 15055111u, 14892937u, 14732511u, 14573813u, 14416824u, 14261526u,
    14107901u, 13955931u, 13805598u, 13656884u, 13509772u, 13364245u, 13220286u, 13077877u,
    12937002u, 12797645u, 12659789u, 12523418u, 12388516u, 12255067u, 12123055u, 11992466u,
    11863283u, 11735492u, 11609078u, 11484025u, 11360319u, 11237946u, 11116891u, 10997140u,
    10878679u, 10761494u, 10645571u, 10530897u, 10417458u, 10305242u, 10194234u, 10084422u,
    9975792u,  9868333u,  9762032u,  9656875u,  9552851u,  9449948u,  9348154u,  9247455u,
    9147842u,  9049301u,  8951823u,  8855394u,  8760003u,  8665641u,  8572295u,  8479954u,
    8388608u,
};

static uint32_t fnv1a(uint32_t h, uint32_t value, unsigned n_bytes) {
  for (unsigned i = 0; i < n_bytes; ++i) {
    h ^= (value >> (8u * i)) & 0xFFu;
    h *= FNV_PRIME;
  }
  return h;
}

uint32_t pour_policy_weights_hash(const pour_policy_weights_t *weights) {
  const int32_t header[9] = {
      POUR_WEIGHTS_FORMAT_VERSION,  POUR_POLICY_N_FEATURES,       (int32_t)weights->n_actions,
      (int32_t)weights->w_frac_bits, (int32_t)weights->decision_period_ms, weights->norm.theta_min_urad,
      weights->norm.theta_max_urad, weights->norm.omega_max_urad_s, weights->tau_max_mnm,
  };
  uint32_t h = FNV_OFFSET_BASIS;
  for (unsigned i = 0; i < 9u; ++i) {
    h = fnv1a(h, (uint32_t)header[i], 4u);
  }
  const unsigned n_w = (unsigned)POUR_POLICY_N_FEATURES * weights->n_actions;
  for (unsigned i = 0; i < n_w; ++i) {
    h = fnv1a(h, (uint16_t)weights->w[i], 2u);
  }
  for (unsigned i = 0; i < weights->n_actions; ++i) {
    h = fnv1a(h, (uint16_t)weights->action_levels[i], 2u);
  }
  return h;
}

pour_status_t pour_policy_weights_validate(const pour_policy_weights_t *weights) {
  if (weights == NULL || weights->w == NULL || weights->action_levels == NULL) {
    return POUR_EINVAL;
  }
  if (weights->n_actions < POUR_POLICY_MIN_ACTIONS || weights->n_actions > POUR_POLICY_MAX_ACTIONS) {
    return POUR_ESHAPE;
  }
  if (weights->w_frac_bits > 15u) {
    return POUR_EFORMAT;
  }
  if (weights->decision_period_ms < 1u || weights->tau_max_mnm <= 0) {
    return POUR_EINVAL;
  }
  if (pour_obs_norm_validate(&weights->norm) != POUR_OK) {
    return POUR_EINVAL;
  }
  /* Levels are torque fractions in increasing order: action i+1 always pushes harder than action i. */
  for (unsigned i = 1; i < weights->n_actions; ++i) {
    if (weights->action_levels[i] <= weights->action_levels[i - 1u]) {
      return POUR_EINVAL;
    }
  }
  if (pour_policy_weights_hash(weights) != weights->content_hash) {
    return POUR_ECORRUPT;
  }
  return POUR_OK;
}

/* Whether every partial sum of round((x·W)[a] / 2^f), the rounding's half included and in any order of the
 * terms, lies in int32 for every x in [0, 32767]^5: each sum is between the bias term plus half plus the
 * negative terms' extreme and the same plus the positive terms' (x >= 0), so those two bounds decide. */
static bool sums_fit_i32(const pour_policy_weights_t *weights) {
  const unsigned n = weights->n_actions;
  const int64_t half = weights->w_frac_bits > 0u ? (int64_t)1 << (weights->w_frac_bits - 1u) : 0;
  for (unsigned a = 0; a < n; ++a) {
    const int64_t base = (int64_t)weights->w[POUR_OBS_N * n + a] * POUR_Q15_ONE_INT + half;
    int64_t lo = base;
    int64_t hi = base;
    for (unsigned k = 0; k < (unsigned)POUR_OBS_N; ++k) {
      const int64_t term = (int64_t)weights->w[k * n + a] * POUR_Q15_MAX;
      if (term < 0) {
        lo += term;
      } else {
        hi += term;
      }
    }
    if (lo < INT32_MIN || hi > INT32_MAX) {
      return false;
    }
  }
  return true;
}

pour_status_t pour_policy_init(pour_policy_t *policy, const pour_policy_weights_t *weights,
                               pour_policy_mode_t mode, uint32_t seed) {
  if (policy == NULL || (mode != POUR_POLICY_GREEDY && mode != POUR_POLICY_SAMPLED)) {
    return POUR_EINVAL;
  }
  const pour_status_t status = pour_policy_weights_validate(weights);
  if (status != POUR_OK) {
    return status;
  }
  policy->weights = weights;
  policy->mode = mode;
  policy->rng = seed != 0u ? seed : DEFAULT_SEED;
  policy->sums_fit_i32 = sums_fit_i32(weights);
  policy->half = weights->w_frac_bits > 0u ? (int32_t)(1u << (weights->w_frac_bits - 1u)) : 0;
  const unsigned n = weights->n_actions;
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    for (unsigned k = 0; k < 3u; ++k) { /* feature pairs (0, 1), (2, 3), (4, bias) of action a */
      policy->packed[a][k] = a < n ? (uint16_t)weights->w[2u * k * n + a] |
                                         (uint32_t)(uint16_t)weights->w[(2u * k + 1u) * n + a] << 16
                                   : 0u;
    }
  }
  return POUR_OK;
}

void pour_policy_logits(const pour_policy_weights_t *weights, const pour_obs_t *obs, int32_t *logits) {
  const unsigned n = weights->n_actions;
  const unsigned f = weights->w_frac_bits;
  const int16_t *w = weights->w;
  /* x is Q15 in [0, 32767] (never negative), w is int16 Q(15-f).f, the bias input is 32768 (1.0), so
   * |x w| <= 32767 * 32768 and the exact sum has |acc| <= 6 * 2^30 < 2^33 (Q(15+f)): an int64
   * accumulator. It is formed from three pair sums that are each exact in int32: two observation
   * terms stay within 2 * 32767 * 32768 < 2^31, and x4 w4 + 32768 w5 lies in
   * [-32768 * 65535, 32767 * 65535]. The pairs are computed row by row (few live registers on the
   * Cortex-M4, 32-bit multiply-accumulates). */
  int32_t s01[POUR_POLICY_MAX_ACTIONS];
  int32_t s23[POUR_POLICY_MAX_ACTIONS];
  const int32_t x0 = obs->x[0], x1 = obs->x[1];
  for (unsigned a = 0; a < n; ++a) {
    s01[a] = x0 * w[a] + x1 * w[n + a];
  }
  const int32_t x2 = obs->x[2], x3 = obs->x[3];
  for (unsigned a = 0; a < n; ++a) {
    s23[a] = x2 * w[2u * n + a] + x3 * w[3u * n + a];
  }
  const int32_t x4 = obs->x[4];
  const int16_t *w4 = w + 4u * n;
  const int16_t *w5 = w + 5u * n;
  if (f >= 2u) {
    /* round(acc / 2^f) without 64-bit arithmetic: floor((s + t + u + half) / 2^f) equals
     * (s >> f) + (t >> f) + (u >> f) + (((s & m) + (t & m) + (u & m) + half) >> f), m = 2^f - 1.
     * With f >= 2 the result, |acc| / 4 < 2^31, never needs saturating. */
    const int32_t m = (int32_t)((1u << f) - 1u);
    const int32_t half = (int32_t)(1u << (f - 1u));
    for (unsigned a = 0; a < n; ++a) {
      const int32_t u = x4 * w4[a] + POUR_Q15_ONE_INT * w5[a];
      const int32_t s = s01[a];
      const int32_t t = s23[a];
      logits[a] = (s >> f) + (t >> f) + (u >> f) + (((s & m) + (t & m) + (u & m) + half) >> f);
    }
  } else {
    const int64_t half = f > 0u ? 1 : 0;
    for (unsigned a = 0; a < n; ++a) {
      const int64_t acc = (int64_t)s01[a] + s23[a] + (x4 * w4[a] + POUR_Q15_ONE_INT * w5[a]);
      logits[a] = pour_sat_i32((acc + half) >> f);
    }
  }
}

/* exp(-d) for d = max - logit >= 0 (Q16.15 difference, as uint32), in Q16 (1.0 = 65536).
 * exp(-d) = 2^-y with y = round(d * log2(e)) in Q15, log2(e) in Q16 = 94548 = 65536 + 4 * 7253, so
 * y = (d * 94548 + 32768) >> 16 = d + ((d * 7253 + 8192) >> 14) exactly, in 32 bits for the d that
 * matter. y = k + r: 2^-r from the 65-entry Q24 table with linear interpolation over 9 fraction bits
 * (error < 1 LSB of Q16), then >> (8 + k) rounded. k > 16 (d >= 386124) gives 0, below half a Q16 LSB. */
#define EXP_D_CUTOFF 386124u
static uint32_t exp_neg_q16(uint32_t d) {
  if (d >= EXP_D_CUTOFF) {
    return 0u;
  }
  const uint32_t y = d + ((d * 7253u + 8192u) >> 14); /* d * 7253 < 2^32 below the cutoff */
  const uint32_t k = y >> 15;
  const uint32_t r = y & 0x7FFFu;
  const uint32_t j = r >> 9;
  const uint32_t frac = r & 0x1FFu;
  const uint32_t step = exp2_neg_q24[j] - exp2_neg_q24[j + 1u]; /* < 2^18: step * 511 fits */
  const uint32_t v = exp2_neg_q24[j] - ((step * frac + 256u) >> 9);
  const uint32_t shift = 8u + k;
  return (v + (1u << (shift - 1u))) >> shift;
}

void pour_policy_softmax_q15(const int32_t *logits, unsigned n, q15_t *probs) {
  int32_t max = logits[0];
  for (unsigned a = 1; a < n; ++a) {
    if (logits[a] > max) {
      max = logits[a];
    }
  }
  uint32_t e[POUR_POLICY_MAX_ACTIONS];
  uint32_t sum = 0u; /* >= 65536 (the max's term), <= 16 * 65536 */
  for (unsigned a = 0; a < n; ++a) {
    e[a] = exp_neg_q16((uint32_t)max - (uint32_t)logits[a]); /* exact: 0 <= max - logit < 2^32 */
    sum += e[a];
  }
  /* p = round(32768 * e / sum): e * 32768 <= 2^31 and sum / 2 < 2^20, so the numerator fits uint32 and
   * the divide is one UDIV on the Cortex-M4. Each p is within half an LSB of the exact ratio, so
   * |sum(p) - 32768| <= n/2 LSB; p = 32768 (one action holds all the mass) saturates to 32767. */
  for (unsigned a = 0; a < n; ++a) {
    const uint32_t p = (e[a] * 32768u + sum / 2u) / sum;
    probs[a] = (q15_t)(p > (uint32_t)POUR_Q15_MAX ? (uint32_t)POUR_Q15_MAX : p);
  }
}

unsigned pour_policy_argmax(const int32_t *logits, unsigned n) {
  unsigned best = 0;
  int32_t top = logits[0];
  for (unsigned a = 1; a < n; ++a) {
    const int32_t v = logits[a];
    if (v > top) { /* strict: a tie keeps the lower index */
      top = v;
      best = a;
    }
  }
  return best;
}

uint32_t pour_policy_xorshift32(uint32_t *state) {
  uint32_t x = *state;
  x ^= x << 13;
  x ^= x >> 17;
  x ^= x << 5;
  *state = x;
  return x;
}

unsigned pour_policy_sample(const q15_t *probs, unsigned n, uint32_t *rng) {
  int32_t total = 0; /* probabilities are >= 0 */
  for (unsigned a = 0; a < n; ++a) {
    total += probs[a];
  }
  /* u uniform in [0, total) from the top of the 32-bit draw; actions with p = 0 are never picked. */
  const int32_t u = (int32_t)(((uint64_t)pour_policy_xorshift32(rng) * (uint32_t)total) >> 32);
  int32_t cum = 0;
  for (unsigned a = 0; a < n; ++a) {
    cum += probs[a];
    if (u < cum) {
      return a;
    }
  }
  return n - 1u; /* only when every probability is 0 (never after pour_policy_softmax_q15) */
}

void pour_policy_fill_probs(const pour_policy_t *policy, pour_policy_eval_t *out) {
  const unsigned n = policy->weights->n_actions;
  pour_policy_softmax_q15(out->logits, n, out->probs);
  for (unsigned a = n; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    out->probs[a] = 0;
  }
}

/* The logits of pour_policy_logits when sums_fit_i32 holds (pour_policy_init decides), from the weights
 * pour_policy_init packed per action: {w0 | w1 << 16, w2 | w3 << 16, w4 | bias << 16}. Each action's exact sum
 * in one int32, (half + Σ x w + 32768 bias) >> f, no saturation needed. On the Cortex-M4 three words per action
 * (one LDM) and three dual multiply-accumulates (ACLE __smlad twice, then __smlsd with (x4, -32768): x4 w4 -
 * (-32768) bias); their additions wrap, but the exact sum fits int32, so the result is exact. The portable path
 * computes the same integers from the halves. Returns the argmax as pour_policy_argmax finds it (strictly
 * greater: a tie keeps the lower index). */
static unsigned logits_i32(const pour_policy_t *policy, const pour_obs_t *obs, int32_t *logits) {
  const pour_policy_weights_t *weights = policy->weights;
  const unsigned n = weights->n_actions;
  const unsigned f = weights->w_frac_bits;
  const int32_t half = policy->half;
  const uint32_t *pw = policy->packed[0];
  const uint32_t *const end = pw + 3u * n;
  int32_t *o = logits;
  const int32_t *top_at = logits;
  int32_t top = INT32_MIN; /* logits[0] >= it: index 0 unless a later logit is strictly greater */
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP
  const int32_t x01 = (int32_t)((uint16_t)obs->x[0] | (uint32_t)(uint16_t)obs->x[1] << 16);
  const int32_t x23 = (int32_t)((uint16_t)obs->x[2] | (uint32_t)(uint16_t)obs->x[3] << 16);
  const int32_t x45 = (int32_t)((uint16_t)obs->x[4] | 0x80000000u); /* (x4, -32768) */
  for (; pw != end; ++o) {
    /* The action's three words in one LDM that steps pw on (the compiler issues three LDRs and an ADD);
     * LDM wants its registers in ascending order. */
    register uint32_t w0 __asm__("r4");
    register uint32_t w1 __asm__("r5");
    register uint32_t w2 __asm__("r6");
    __asm__("ldmia %3!, {%0, %1, %2}" : "=r"(w0), "=r"(w1), "=r"(w2), "+r"(pw) : "m"(*(const uint32_t(*)[3])pw));
    int32_t s = __smlad(x01, (int32_t)w0, half);
    s = __smlad(x23, (int32_t)w1, s);
    s = __smlsd(x45, (int32_t)w2, s) >> f;
#else
  for (; pw != end; pw += 3, ++o) {
    /* The bias first: every partial sum then includes it, as sums_fit_i32's bound does (a sum of the
     * observations' terms alone may leave int32). Each pair's sum, |x w + x' w'| <= 2 * 32767 * 32768, fits. */
    int32_t s = half + (int16_t)(uint16_t)(pw[2] >> 16) * POUR_Q15_ONE_INT;
    for (unsigned k = 0; k < 3u; ++k) {
      const int32_t lo = (int16_t)(uint16_t)(pw[k] & 0xFFFFu);
      const int32_t hi = (int16_t)(uint16_t)(pw[k] >> 16);
      s += obs->x[2u * k] * lo + (k < 2u ? obs->x[2u * k + 1u] * hi : 0);
    }
    s >>= f;
#endif
    *o = s;
    if (s > top) {
      top = s;
      top_at = o;
    }
  }
  return (unsigned)(top_at - logits);
}

bool pour_policy_decide(pour_policy_t *policy, const pour_obs_t *obs, pour_policy_eval_t *out) {
  const pour_policy_weights_t *w = policy->weights;
  const unsigned n = w->n_actions;
  unsigned best;
  if (policy->sums_fit_i32) {
    best = logits_i32(policy, obs, out->logits);
  } else {
    pour_policy_logits(w, obs, out->logits);
    best = pour_policy_argmax(out->logits, n);
  }
  if (policy->mode == POUR_POLICY_SAMPLED) {
    pour_policy_fill_probs(policy, out);
    out->action = (uint8_t)pour_policy_sample(out->probs, n, &policy->rng);
    return true;
  }
  out->action = (uint8_t)best;
  return false;
}

void pour_policy_eval(pour_policy_t *policy, const pour_obs_t *obs, pour_policy_eval_t *out) {
  for (unsigned a = policy->weights->n_actions; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    out->logits[a] = 0;
  }
  if (!pour_policy_decide(policy, obs, out)) {
    pour_policy_fill_probs(policy, out);
  }
}
