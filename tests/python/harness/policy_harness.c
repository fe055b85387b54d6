/* SPDX-License-Identifier: MIT */
/* Runs the firmware core's greedy policy on states read from stdin, for the exporter's bit-exactness test.
 * Build: cc -I firmware/include -DPOUR_WEIGHTS_HEADER='"weights.h"' this.c firmware/src/{fixed,obs,policy}.c
 * The header is included here, in a translation unit the test compiles with the strictest warnings.
 * Input lines: theta_urad omega_urad_s v_rot_q15 v_tgt_q15 v_spill_q15.
 * Output lines: the five Q15 observations, the n logits (Q16.15), the n probabilities (Q15), the action. */
#include <stdio.h>
#include <stdlib.h>

#include "pour/obs.h"
#include "pour/policy.h"

#include POUR_WEIGHTS_HEADER

static const pour_policy_weights_t weights = {
    (uint8_t)POUR_WEIGHTS_N_ACTIONS,
    (uint8_t)POUR_WEIGHTS_W_FRAC_BITS,
    (uint16_t)POUR_WEIGHTS_DECISION_PERIOD_MS,
    &pour_weights_w[0][0],
    pour_weights_action_levels_q15,
    {(int32_t)POUR_WEIGHTS_THETA_MIN_URAD, (int32_t)POUR_WEIGHTS_THETA_MAX_URAD,
     (int32_t)POUR_WEIGHTS_OMEGA_MAX_URAD_S},
    (int32_t)POUR_WEIGHTS_TAU_MAX_MNM,
    (uint32_t)POUR_WEIGHTS_CONTENT_HASH,
};

int main(void) {
  pour_policy_t policy;
  pour_status_t st = pour_policy_init(&policy, &weights, POUR_POLICY_GREEDY, 1u);
  if (st != POUR_OK) {
    fprintf(stderr, "policy_harness: pour_policy_init: %s\n", pour_status_name(st));
    return 2;
  }
  long th, om, vr, vt, vs;
  while (scanf("%ld %ld %ld %ld %ld", &th, &om, &vr, &vt, &vs) == 5) {
    pour_state_t s = {0u, (int32_t)th, (int32_t)om, (q15_t)vr, (q15_t)vt, (q15_t)vs};
    pour_obs_t obs;
    pour_policy_eval_t ev;
    pour_obs_quantize(&weights.norm, &s, &obs);
    pour_policy_eval(&policy, &obs, &ev);
    for (unsigned i = 0; i < POUR_OBS_N; i++) printf("%d ", (int)obs.x[i]);
    for (unsigned a = 0; a < weights.n_actions; a++) printf("%ld ", (long)ev.logits[a]);
    for (unsigned a = 0; a < weights.n_actions; a++) printf("%d ", (int)ev.probs[a]);
    printf("%u\n", (unsigned)ev.action);
  }
  return 0;
}
