/* SPDX-License-Identifier: MIT */
#include "pour/obs.h"

#include <stddef.h>

pour_status_t pour_obs_norm_validate(const pour_obs_norm_t *norm) {
  if (norm == NULL) {
    return POUR_EINVAL;
  }
  /* The scaling below works in int64 on differences of int32 values, so any positive range is safe;
   * only empty or inverted ranges are refused. */
  if ((int64_t)norm->theta_max_urad - (int64_t)norm->theta_min_urad <= 0) {
    return POUR_EINVAL;
  }
  if (norm->omega_max_urad_s <= 0) {
    return POUR_EINVAL;
  }
  return POUR_OK;
}

#if defined(__GNUC__)
#define OBS_INLINE static inline __attribute__((always_inline)) /* once per decision: no call around it */
#else
#define OBS_INLINE static inline
#endif

/* 0 < num < d < 2^24: 32768 num = (num << 8) << 7, divided in two 32-bit steps (each one UDIV on the Cortex-M4,
 * where a 64-bit divide is a library call of ~100 instructions), all in 32 bits. */
OBS_INLINE q15_t ratio_q15_small(uint32_t num, uint32_t d) {
  const uint32_t a = num << 8; /* < 2^32 */
  const uint32_t q1 = a / d;
  const uint32_t b = (a - q1 * d) << 7; /* the remainder is < 2^24, so b < 2^31 */
  const uint32_t q2 = b / d;
  const uint32_t r = b - q2 * d;                               /* < 2^24: 2 r fits */
  const uint32_t q = (q1 << 7) + q2 + (2u * r >= d ? 1u : 0u); /* <= 32768 */
  return (q15_t)(q > (uint32_t)POUR_Q15_MAX ? (uint32_t)POUR_Q15_MAX : q);
}

/* round(32768 * num / den) for den > 0, saturated to [0, 32767]: the Q15 of num/den clipped to [0, 1).
 * Round half up: with Q = floor(32768 num / den) and R its remainder, the result is Q + (2R >= den),
 * which equals Python's (2 * num * 32768 + den) // (2 * den). */
static q15_t ratio_q15(int64_t num, int64_t den) {
  if (num <= 0) {
    return 0;
  }
  if (num >= den) {
    return POUR_Q15_MAX;
  }
  if (den < ((int64_t)1 << 24)) {
    return ratio_q15_small((uint32_t)num, (uint32_t)den);
  }
  const int64_t scaled = num * POUR_Q15_ONE_INT; /* num < 2^33: < 2^48 */
  int64_t q = scaled / den;
  const int64_t r = scaled - q * den;
  q += 2 * r >= den ? 1 : 0; /* q <= 32768 */
  return (q15_t)(q > POUR_Q15_MAX ? POUR_Q15_MAX : q);
}

/* ratio_q15 for 0 < num and 0 < den, each below 2^32, in 32-bit compares: with den < 2^24 (the usual ranges,
 * 2.4 rad of tilt and 8 rad/s of speed) no 64-bit arithmetic at all. */
OBS_INLINE q15_t ratio_q15_u32(uint32_t num, uint32_t den) {
  if (num >= den) {
    return POUR_Q15_MAX;
  }
  return den < (1u << 24) ? ratio_q15_small(num, den) : ratio_q15((int64_t)num, (int64_t)den);
}

static q15_t volume_q15(q15_t v) { return (q15_t)(v < 0 ? 0 : v); }

void pour_obs_quantize(const pour_obs_norm_t *norm, const pour_state_t *state, pour_obs_t *obs) {
  /* In 32 bits, exactly: max > min and omega_max > 0 (pour_obs_norm_validate), so the span, 2 omega_max and,
   * past the lower end, each offset lie in (0, 2^32): uint32 differences and sums of the int32s are exact. */
  const int32_t theta = state->theta_urad, omega = state->omega_urad_s;
  const int32_t theta_min = norm->theta_min_urad, omega_max = norm->omega_max_urad_s;
  obs->x[0] = theta <= theta_min ? 0
                                 : ratio_q15_u32((uint32_t)theta - (uint32_t)theta_min,
                                                 (uint32_t)norm->theta_max_urad - (uint32_t)theta_min);
  obs->x[1] = omega <= -omega_max ? 0 : ratio_q15_u32((uint32_t)omega + (uint32_t)omega_max, 2u * (uint32_t)omega_max);
  obs->x[2] = volume_q15(state->v_rotating);
  obs->x[3] = volume_q15(state->v_target);
  obs->x[4] = volume_q15(state->v_spill);
}
