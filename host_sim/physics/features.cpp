// SPDX-License-Identifier: MIT
// The float policy's features: the one float normalisation of the host (the firmware's fixed-point one is
// pour_obs_quantize), used by the rollout and, through ctypes, by the trainer.
#include "poursim/poursim.h"

namespace {

double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

} // namespace

extern "C" void poursim_features(const poursim_policy_t *p, double theta, double omega, double v_rotating,
                                 double v_target, double v_spill, double x[POURSIM_N_FEATURES]) {
  x[0] = clamp01((theta - p->theta_min) / (p->theta_max - p->theta_min));
  x[1] = clamp01((omega + p->omega_max) / (2.0 * p->omega_max));
  x[2] = clamp01(v_rotating);
  x[3] = clamp01(v_target);
  x[4] = clamp01(v_spill);
  x[5] = 1.0;
}
