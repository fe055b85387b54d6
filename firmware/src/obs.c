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
 * num, den < 2^33, so 2 * num * 32768 < 2^50 never overflows int64. Round half up, like Python's
 * (2 * num * 32768 + den) // (2 * den). */
static q15_t ratio_q15(int64_t num, int64_t den) {
  if (num <= 0) {
    return 0;
  }
  if (num >= den) {
    return POUR_Q15_MAX;
  }
  const int64_t q = (num * (2 * POUR_Q15_ONE_INT) + den) / (2 * den);
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
