/* SPDX-License-Identifier: MIT */
#include "weights_builtin.h"

#include POUR_WEIGHTS_INCLUDE

static const pour_policy_weights_t builtin = {
    .n_actions = POUR_WEIGHTS_N_ACTIONS,
    .w_frac_bits = POUR_WEIGHTS_W_FRAC_BITS,
    .decision_period_ms = POUR_WEIGHTS_DECISION_PERIOD_MS,
    .w = &pour_weights_w[0][0],
    .action_levels = pour_weights_action_levels_q15,
    .norm = {.theta_min_urad = POUR_WEIGHTS_THETA_MIN_URAD,
             .theta_max_urad = POUR_WEIGHTS_THETA_MAX_URAD,
             .omega_max_urad_s = POUR_WEIGHTS_OMEGA_MAX_URAD_S},
    .tau_max_mnm = POUR_WEIGHTS_TAU_MAX_MNM,
    .content_hash = POUR_WEIGHTS_CONTENT_HASH,
};

const pour_policy_weights_t *pour_weights_builtin(void) { return &builtin; }

const char *pour_weights_builtin_path(void) { return POUR_WEIGHTS_INCLUDE; }
