/* SPDX-License-Identifier: MIT */
/* The firmware core (firmware/src, linked into libpoursim) for languages that must not mirror its structs:
 * opaque handles and accessors. Configs are byte blocks of poursim_fw_config_size() bytes whose fields are
 * read and set by name ("safety.tau_limit"); the envelope, the estimator and the controller are handles.
 * Only plain data records cross as structs: pour_sensors_t (a sample in), pour_state_t (the estimate out),
 * pour_control_input_t and pour_control_output_t (a tick's inputs and outputs); poursim_sizeof() gives
 * each one's size so that a binding can check its copy. */
#ifndef POURSIM_CORE_H
#define POURSIM_CORE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "pour/control.h" /* the firmware headers carry no C++ guards of their own */
#include "poursim/poursim.h"

/* sizeof the named record ("pour_state_t", "poursim_episode_t", ...) as this library was built, 0 for a
 * name it does not export. */
size_t poursim_sizeof(const char *type_name);

/* ---- The core's config (pour_control_config_t) as an opaque block. ---- */
size_t poursim_fw_config_size(void);
/* The firmware's defaults (pour_control_default_config), or with rig != NULL its config for that simulated
 * rig: the one place that adapts the firmware to the simulator (its encoder). */
void poursim_fw_config_init(void *config, const poursim_config_t *rig);
/* The i-th field's dotted name (0 .. n-1), NULL past the last. */
const char *poursim_fw_config_field(int i);
/* Sets / reads a field by name. POURSIM_EINVAL for an unknown name or a value its type cannot hold. */
int poursim_fw_config_set(void *config, const char *name, int64_t value);
int poursim_fw_config_get(const void *config, const char *name, int64_t *value);

/* ---- The safety envelope (pour_safety_t) on config's "safety.*" fields. ---- */
typedef struct poursim_envelope poursim_envelope_t;
/* NULL with a message in err when the core refuses the config (its pour_status_t name). */
poursim_envelope_t *poursim_envelope_create(const void *config, char *err, size_t err_len);
void poursim_envelope_destroy(poursim_envelope_t *env);
int16_t poursim_envelope_apply(poursim_envelope_t *env, int16_t requested, int32_t theta_urad, int32_t omega_urad_s);
void poursim_envelope_force(poursim_envelope_t *env, int16_t torque);
uint8_t poursim_envelope_active(const poursim_envelope_t *env); /* POUR_LIMIT_* of the last command */
int16_t poursim_envelope_torque(const poursim_envelope_t *env); /* the last command, Q15 */
/* The speed band the last command was held in [µrad/s]: [*floor, *ceiling]. */
void poursim_envelope_band(const poursim_envelope_t *env, int32_t *floor_urad_s, int32_t *ceiling_urad_s);

/* ---- The sensor estimator (pour_estimator_t) on config's "sensors.*" fields. ---- */
typedef struct poursim_estimator poursim_estimator_t;
poursim_estimator_t *poursim_estimator_create(const void *config, char *err, size_t err_len);
void poursim_estimator_destroy(poursim_estimator_t *est);
void poursim_estimator_reset(poursim_estimator_t *est);
/* pour_estimator_update: 1 and *state filled, or 0 for a sample the firmware refuses. */
int poursim_estimator_update(poursim_estimator_t *est, const pour_sensors_t *sample, pour_state_t *state);

/* ---- The control pipeline (pour_control_t). ---- */
typedef struct poursim_core poursim_core_t;
/* With n_actions > 0: the fixed-point policy of those weights (w [6][n_actions] Q(15-f).f, levels Q15,
 * copied) decides (pour_control_init). With n_actions == 0: decisions come from outside
 * (poursim_core_request) every decision_period_ms ticks of RUN (pour_control_init_external); the other
 * weight arguments are then ignored. NULL with a message in err when the core refuses. */
poursim_core_t *poursim_core_create(const void *config, int n_actions, int w_frac_bits, int decision_period_ms,
                                    const int16_t *w, const int16_t *levels, int32_t theta_min_urad,
                                    int32_t theta_max_urad, int32_t omega_max_urad_s, int32_t tau_max_mnm,
                                    uint32_t content_hash, char *err, size_t err_len);
void poursim_core_destroy(poursim_core_t *core);
/* The pipeline's stages (control.h): update returns 1 when a decision is due. */
int poursim_core_update(poursim_core_t *core, const pour_control_input_t *in);
void poursim_core_state(const poursim_core_t *core, pour_state_t *state);
void poursim_core_decide(poursim_core_t *core);
void poursim_core_request(poursim_core_t *core, uint8_t action, int16_t torque);
void poursim_core_shape(poursim_core_t *core, pour_control_output_t *out);
/* pour_control_step: update, the policy's decision when due, shape. */
void poursim_core_step(poursim_core_t *core, const pour_control_input_t *in, pour_control_output_t *out);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_CORE_H */
