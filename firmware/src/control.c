/* SPDX-License-Identifier: MIT */
#include "pour/control.h"

#include <stddef.h>

/* docs/safety.md gives the reasons for each default. */
#define DEFAULT_INPUT_TIMEOUT_MS 20u
#define DEFAULT_SEED 1u
#define DEFAULT_PLAUSIBLE_THETA_URAD 3141593   /* π: the tilt cannot pass half a turn */
#define DEFAULT_PLAUSIBLE_OMEGA_URAD_S 50000000 /* 50 rad/s, ~8 turns/s */
#define DEFAULT_PLAUSIBLE_VOLUME_SUM 32896      /* 1.0 + 128 LSB (0.4 %) of slack for rounding */

pour_control_config_t pour_control_default_config(void) {
  pour_control_config_t config;
  config.safety = pour_safety_default_config();
  config.input_timeout_ms = DEFAULT_INPUT_TIMEOUT_MS;
  config.safe_torque = 0;
  config.policy_mode = POUR_POLICY_GREEDY;
  config.seed = DEFAULT_SEED;
  config.plausible_theta_urad = DEFAULT_PLAUSIBLE_THETA_URAD;
  config.plausible_omega_urad_s = DEFAULT_PLAUSIBLE_OMEGA_URAD_S;
  config.plausible_volume_sum = DEFAULT_PLAUSIBLE_VOLUME_SUM;
  return config;
}

/* The run's state as at power-on: no state seen, zero torque, the decision schedule and the PRNG
 * from their start (init and an accepted reset; config and weights were validated at init). */
static void start_afresh(pour_control_t *ctl) {
  (void)pour_safety_init(&ctl->safety, &ctl->config.safety);
  (void)pour_policy_init(&ctl->policy, ctl->policy.weights, ctl->config.policy_mode, ctl->config.seed);
  ctl->ms_since_fresh = 0u;
  ctl->ms_to_decision = 0u;
  const pour_state_t zero_state = {0u, 0, 0, 0, 0, 0};
  ctl->state = zero_state;
  for (unsigned i = 0; i < POUR_OBS_N; ++i) {
    ctl->obs.x[i] = 0;
  }
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    ctl->eval.logits[a] = 0;
    ctl->eval.probs[a] = 0;
  }
  ctl->eval.action = 0u;
}

pour_status_t pour_control_init(pour_control_t *ctl, const pour_control_config_t *config,
                                const pour_policy_weights_t *weights) {
  if (ctl == NULL || config == NULL) {
    return POUR_EINVAL;
  }
  const pour_control_config_t *c = config;
  if (c->input_timeout_ms < 1u || c->plausible_theta_urad <= 0 || c->plausible_omega_urad_s <= 0 ||
      c->plausible_volume_sum <= 0) {
    return POUR_EINVAL;
  }
  if (pour_safety_init(&ctl->safety, &c->safety) != POUR_OK) {
    return POUR_EINVAL;
  }
  if (c->safe_torque > c->safety.tau_limit || c->safe_torque < -c->safety.tau_limit) {
    return POUR_EINVAL;
  }
  const pour_status_t status = pour_policy_init(&ctl->policy, weights, c->policy_mode, c->seed);
  if (status != POUR_OK) {
    return status;
  }
  ctl->config = *c;
  ctl->mode = POUR_MODE_IDLE;
  ctl->faults = 0u;
  ctl->tick = 0u;
  ctl->resets_refused = 0u;
  start_afresh(ctl);
  return POUR_OK;
}

static int32_t abs_i32_sat(int32_t x) { return x < 0 ? (x == INT32_MIN ? INT32_MAX : -x) : x; }

static bool plausible(const pour_control_config_t *c, const pour_state_t *s) {
  if (abs_i32_sat(s->theta_urad) > c->plausible_theta_urad ||
      abs_i32_sat(s->omega_urad_s) > c->plausible_omega_urad_s) {
    return false;
  }
  if (s->v_rotating < 0 || s->v_target < 0 || s->v_spill < 0) {
    return false;
  }
  return (int32_t)s->v_rotating + s->v_target + s->v_spill <= c->plausible_volume_sum;
}

/* Safe torque, at once, unless it would drive further past an angle limit (then zero). */
static q15_t force_safe(pour_control_t *ctl) {
  const pour_safety_config_t *sc = &ctl->config.safety;
  const int32_t theta = ctl->state.theta_urad;
  q15_t torque = ctl->config.safe_torque;
  if ((torque > 0 && theta >= sc->theta_max_urad) || (torque < 0 && theta <= sc->theta_min_urad)) {
    torque = 0;
  }
  pour_safety_force(&ctl->safety, torque);
  return torque;
}

static void fill_output(const pour_control_t *ctl, q15_t torque, pour_control_output_t *out) {
  out->torque = torque;
  out->action = ctl->eval.action;
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    out->probs[a] = ctl->eval.probs[a];
  }
  out->mode = (uint8_t)ctl->mode;
  out->faults = ctl->faults;
  out->limits = ctl->safety.active;
  out->tick = ctl->tick;
}

void pour_control_step(pour_control_t *ctl, const pour_control_input_t *in, pour_control_output_t *out) {
  ctl->tick++;
  if (in->estop) {
    ctl->mode = POUR_MODE_ESTOP;
    ctl->faults |= POUR_FAULT_ESTOP;
    pour_safety_force(&ctl->safety, 0);
    fill_output(ctl, 0, out);
    return;
  }
  if (ctl->mode == POUR_MODE_ESTOP) {
    ctl->mode = POUR_MODE_FAULT;
  }
  if (in->link_fault) {
    /* The transport no longer hears its host: the core, not only the bus output, goes to FAULT, so that
     * nothing keeps ramping behind a substituted output and a later clear cannot release it at once. */
    ctl->faults |= POUR_FAULT_LINK;
    ctl->mode = POUR_MODE_FAULT;
  }
  if (in->clear_faults && ctl->mode == POUR_MODE_FAULT) {
    /* Back to IDLE: RUN (and the timeout) start again only with the next fresh state, from the safe
     * torque the envelope holds now, through the slew limit. */
    ctl->faults = 0u;
    ctl->mode = POUR_MODE_IDLE;
    ctl->ms_since_fresh = 0u;
  }
  if (in->stop && ctl->mode == POUR_MODE_RUN) {
    ctl->mode = POUR_MODE_IDLE;
  }
  if (in->reset) {
    /* Re-initialising under a running policy would drop the envelope's torque in one tick: refused. */
    if (ctl->mode == POUR_MODE_IDLE || ctl->mode == POUR_MODE_FAULT) {
      start_afresh(ctl);
    } else {
      ctl->resets_refused++;
    }
  }

  bool fresh = false;
  if (in->state_fresh) {
    if (plausible(&ctl->config, &in->state)) {
      ctl->state = in->state;
      ctl->ms_since_fresh = 0u;
      fresh = true;
    } else {
      ctl->faults |= POUR_FAULT_BAD_INPUT;
      ctl->mode = POUR_MODE_FAULT;
    }
  } else if (ctl->mode == POUR_MODE_RUN) {
    ctl->ms_since_fresh++;
    if (ctl->ms_since_fresh > ctl->config.input_timeout_ms) {
      ctl->faults |= POUR_FAULT_STALE_INPUT;
      ctl->mode = POUR_MODE_FAULT;
    }
  }

  if (ctl->mode == POUR_MODE_IDLE && fresh) {
    ctl->mode = POUR_MODE_RUN;
    ctl->ms_to_decision = 0u;
  }

  q15_t torque;
  if (ctl->mode == POUR_MODE_RUN) {
    const pour_policy_weights_t *w = ctl->policy.weights;
    if (ctl->ms_to_decision == 0u) {
      pour_obs_quantize(&w->norm, &ctl->state, &ctl->obs);
      pour_policy_eval(&ctl->policy, &ctl->obs, &ctl->eval);
      ctl->ms_to_decision = w->decision_period_ms;
    }
    ctl->ms_to_decision--;
    torque = pour_safety_apply(&ctl->safety, w->action_levels[ctl->eval.action], ctl->state.theta_urad);
  } else {
    torque = force_safe(ctl);
  }
  fill_output(ctl, torque, out);
}
