/* SPDX-License-Identifier: MIT */
/* Run-time loader of weights.h (format v1, docs/weights-h.md): parses and validates the same file the
 * firmware compiles, so host_sim runs exactly the shipped policy without a rebuild. */
#ifndef POURSIM_WEIGHTS_FILE_H
#define POURSIM_WEIGHTS_FILE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "pour/policy.h" /* the firmware headers carry no C++ guards of their own */
#include "poursim/poursim.h"

/* A parsed weights.h. Holds its arrays; poursim_weights_view() lends them to the firmware core. */
typedef struct {
  int32_t format, n_features, n_actions, w_frac_bits, decision_period_ms;
  int32_t theta_min_urad, theta_max_urad, omega_max_urad_s, tau_max_mnm;
  uint32_t content_hash;
  int16_t w[POUR_POLICY_N_FEATURES * POUR_POLICY_MAX_ACTIONS]; /* row-major [6][n_actions], Q(15-f).f */
  q15_t levels[POUR_POLICY_MAX_ACTIONS];                       /* Q15 */
  int has_float_reference;
  float w_float[POUR_POLICY_N_FEATURES * POUR_POLICY_MAX_ACTIONS];
} poursim_weights_file_t;

/* Parses and validates path (shape, Q format, ranges, levels, arrays complete, float reference finite,
 * content hash). On error returns < 0 and writes a message naming the file, line and field into err. */
int poursim_weights_load(const char *path, poursim_weights_file_t *out, char *err, size_t err_len);

/* Same, from text in memory (name is used in messages). */
int poursim_weights_parse(const char *text, size_t len, const char *name, poursim_weights_file_t *out, char *err,
                          size_t err_len);

/* A firmware-core view of the file's arrays (valid while *file lives and is not moved). */
void poursim_weights_view(const poursim_weights_file_t *file, pour_policy_weights_t *view);

/* The float policy the trainer's model means (W / 2^f from the int16 table, levels / 32768), for
 * poursim_rollout. w_out holds 6·n_actions doubles, levels_out n_actions. */
void poursim_weights_float_policy(const poursim_weights_file_t *file, double *w_out, double *levels_out,
                                  poursim_policy_t *policy);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_WEIGHTS_FILE_H */
