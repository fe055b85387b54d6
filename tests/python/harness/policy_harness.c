/* SPDX-License-Identifier: MIT */
/* Runs the firmware core's greedy policy on states read from stdin, for the exporter's bit-exactness test.
 * Build: cc -I firmware/include -DPOUR_WEIGHTS_HEADER='"weights.h"' this.c
 *           firmware/src/{fixed,obs,policy,weights_compiled}.c
 * The header comes in through the firmware's own weights_compiled.c, which the test compiles with the
 * strict warnings, as the image does.
 * Input lines: theta_urad omega_urad_s v_rot_q15 v_tgt_q15 v_spill_q15.
 * Output lines: the five Q15 observations, the n logits (Q16.15), the n probabilities (Q15), the action. */
#include <stdio.h>
#include <stdlib.h>

#include "pour/obs.h"
#include "pour/policy.h"
#include "pour/weights_compiled.h"


int main(void) {
  pour_policy_t policy;
  pour_status_t st = pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u);
  if (st != POUR_OK) {
    fprintf(stderr, "policy_harness: pour_policy_init: %s\n", pour_status_name(st));
    return 2;
  }
  long th, om, vr, vt, vs;
  while (scanf("%ld %ld %ld %ld %ld", &th, &om, &vr, &vt, &vs) == 5) {
    pour_state_t s = {0u, (int32_t)th, (int32_t)om, (q15_t)vr, (q15_t)vt, (q15_t)vs};
    pour_obs_t obs;
    pour_policy_eval_t ev;
    pour_obs_quantize(&pour_weights_compiled.norm, &s, &obs);
    pour_policy_eval(&policy, &obs, &ev);
    for (unsigned i = 0; i < POUR_OBS_N; i++) printf("%d ", (int)obs.x[i]);
    for (unsigned a = 0; a < pour_weights_compiled.n_actions; a++) printf("%ld ", (long)ev.logits[a]);
    for (unsigned a = 0; a < pour_weights_compiled.n_actions; a++) printf("%d ", (int)ev.probs[a]);
    printf("%u\n", (unsigned)ev.action);
  }
  return 0;
}
