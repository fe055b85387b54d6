/* SPDX-License-Identifier: MIT */
#include "state_si.h"

#include <math.h>

int32_t pour_si_to_urad(double rad) {
  const double u = rad * 1e6;
  if (isnan(u) || u >= 2147483647.0) {
    return INT32_MAX;
  }
  if (u <= -2147483648.0) {
    return INT32_MIN;
  }
  return (int32_t)lround(u);
}

q15_t pour_si_to_q15(double fraction) {
  const double q = fraction * 32768.0;
  if (isnan(q)) {
    return POUR_Q15_MIN;
  }
  if (q >= 32767.0) {
    return POUR_Q15_MAX;
  }
  if (q <= 0.0) {
    return 0;
  }
  return (q15_t)nearbyint(q);
}

void pour_state_from_si(pour_state_t *state, int64_t seq, double theta, double omega, double v_rotating,
                        double v_target, double v_spill) {
  state->seq = (uint32_t)((uint64_t)seq & 0xffffffffu);
  state->theta_urad = pour_si_to_urad(theta);
  state->omega_urad_s = pour_si_to_urad(omega);
  state->v_rotating = pour_si_to_q15(v_rotating);
  state->v_target = pour_si_to_q15(v_target);
  state->v_spill = pour_si_to_q15(v_spill);
}
