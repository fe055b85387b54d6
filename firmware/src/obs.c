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

/* round(32768 * num / den) for den > 0, saturated to [0, 32767]: the Q15 of num/den clipped to [0, 1).
 * Round half up: with Q = floor(32768 num / den) and R its remainder, the result is Q + (2R >= den),
 * which equals Python's (2 * num * 32768 + den) // (2 * den). */
#if defined(__GNUC__)
#define OBS_INLINE static inline __attribute__((always_inline)) /* once per decision: no call around it */
#else
#define OBS_INLINE static inline
#endif
OBS_INLINE q15_t ratio_q15(int64_t num, int64_t den) {
  if (num <= 0) {
    return 0;
  }
  if (num >= den) {
    return POUR_Q15_MAX;
  }
  if (den < ((int64_t)1 << 24)) {
    /* 0 < num < den < 2^24: 32768 num = (num << 8) << 7, divided in two 32-bit steps (each one UDIV on
     * the Cortex-M4, where a 64-bit divide is a library call of ~100 instructions), all in 32 bits. */
    const uint32_t d = (uint32_t)den;
    const uint32_t a = (uint32_t)num << 8; /* < 2^32 */
    const uint32_t q1 = a / d;
    const uint32_t b = (a - q1 * d) << 7; /* the remainder is < 2^24, so b < 2^31 */
    const uint32_t q2 = b / d;
    const uint32_t r = b - q2 * d;                       /* < 2^24: 2 r fits */
    const uint32_t q = (q1 << 7) + q2 + (2u * r >= d ? 1u : 0u); /* <= 32768 */
    return (q15_t)(q > (uint32_t)POUR_Q15_MAX ? (uint32_t)POUR_Q15_MAX : q);
  }
  const int64_t scaled = num * POUR_Q15_ONE_INT; /* num < 2^33: < 2^48 */
  int64_t q = scaled / den;
  const int64_t r = scaled - q * den;
  q += 2 * r >= den ? 1 : 0; /* q <= 32768 */
  return (q15_t)(q > POUR_Q15_MAX ? POUR_Q15_MAX : q);
}

static q15_t volume_q15(q15_t v) { return (q15_t)(v < 0 ? 0 : v); }

void pour_obs_quantize(const pour_obs_norm_t *norm, const pour_state_t *state, pour_obs_t *obs) {
  const int64_t theta_span = (int64_t)norm->theta_max_urad - (int64_t)norm->theta_min_urad;
  obs->x[0] = ratio_q15((int64_t)state->theta_urad - (int64_t)norm->theta_min_urad, theta_span);
  obs->x[1] = ratio_q15((int64_t)state->omega_urad_s + (int64_t)norm->omega_max_urad_s,
                        2 * (int64_t)norm->omega_max_urad_s);
  obs->x[2] = volume_q15(state->v_rotating);
  obs->x[3] = volume_q15(state->v_target);
  obs->x[4] = volume_q15(state->v_spill);
}
