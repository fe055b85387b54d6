/* SPDX-License-Identifier: MIT */
#include "pour/control.h"

#include <stddef.h>
#include <string.h>

#include "pour/params.h"

/* docs/safety.md gives the reasons for each default. */
#define DEFAULT_INPUT_TIMEOUT_MS 20u
#define DEFAULT_SEED 1u
#define DEFAULT_PLAUSIBLE_THETA_URAD 3141593   /* π: the tilt cannot pass half a turn */
#define DEFAULT_PLAUSIBLE_OMEGA_URAD_S 50000000 /* 50 rad/s, ~8 turns/s */
#define DEFAULT_PLAUSIBLE_VOLUME_SUM 65536      /* off: load-cell volumes pass 1 under impact and slosh */
#define DEFAULT_RESTART_JUMP_MAX_URAD 52360     /* 3 deg: the gearbox's backlash and the brake's give */

/* The controlled stop's defaults are the declaration's rows of group stop (POUR_PARAMS, pour/params.h). */
#define STOP_ROW_safety(member, type, value)
#define STOP_ROW_stop(member, type, value) config.stop.member = (type)(value);
#define STOP_ROW_sensors(member, type, value)
#define STOP_ROW_supervisor(member, type, value)
#define STOP_ROW_port(member, type, value)
#define STOP_DEFAULT(id, name, unit, def, lo, hi, type, group, member, doc) STOP_ROW_##group(member, type, def)

pour_control_config_t pour_control_default_config(void) {
  pour_control_config_t config;
  config.safety = pour_safety_default_config();
  config.sensors = pour_sensors_default_config();
  config.input_timeout_ms = DEFAULT_INPUT_TIMEOUT_MS;
  config.safe_torque = 0;
  config.policy_mode = POUR_POLICY_GREEDY;
  config.seed = DEFAULT_SEED;
  config.plausible_theta_urad = DEFAULT_PLAUSIBLE_THETA_URAD;
  config.plausible_omega_urad_s = DEFAULT_PLAUSIBLE_OMEGA_URAD_S;
  config.plausible_volume_sum = DEFAULT_PLAUSIBLE_VOLUME_SUM;
  config.restart_jump_max_urad = DEFAULT_RESTART_JUMP_MAX_URAD;
  config.supervisor = pour_supervisor_default_config();
  POUR_PARAMS(STOP_DEFAULT)
  config.experiment = pour_experiment_default_config();
  return config;
}

/* No experiment armed or running. The estimator still takes an empty bucket for one (the identify
 * experiment's stays empty, held or stopping) until a Reset starts a run that needs liquid. */
static void end_experiment(pour_control_t *ctl) { ctl->experiment.kind = (uint8_t)POUR_EXPERIMENT_NONE; }

/* The run's state as at power-on: no state seen, zero torque, the decision schedule and the PRNG
 * from their start (init and an accepted reset; config and weights were validated at init). */
static void start_afresh(pour_control_t *ctl) {
  /* The envelope starts again from the command on the wire, not from the safe torque or zero: a run that
   * starts in the same tick ramps from what the motor has now, through the slew limit. */
  const q15_t on_wire = ctl->safety.torque;
  pour_safety_restart(&ctl->safety); /* validated at init */
  pour_safety_force(&ctl->safety, on_wire);
  /* The policy as init left it: only its PRNG moves during a run (the weights were validated at init, and
   * validating them again here, their content hash, would cost a Reset's tick ~2,700 instructions more than a
   * decision's on the Cortex-M4: virtual_board --profile). */
  ctl->policy.rng = ctl->policy_rng0;
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
  ctl->probs_pending = false;
  ctl->decision_due = false;
  ctl->request = ctl->config.safe_torque;
  pour_supervisor_restart(&ctl->supervisor);
  pour_estimator_reset(&ctl->estimator);
  ctl->stop_ms = 0u;
  ctl->stopped = false;
  ctl->held = false;
  end_experiment(ctl); /* a Reset disarms it too */
  pour_estimator_expect_empty(&ctl->estimator, false);
}

static bool stop_config_ok(const pour_stop_config_t *s) {
  return s->torque_max > 0 && s->return_speed_urad_s > 0 && s->return_gain_per_s >= 1u && s->gain > 0 &&
         s->rest_theta_urad > 0 && s->rest_omega_urad_s > 0 && s->timeout_ms >= 1u;
}

/* Validates the config and takes it; the policy (or none) is the caller's. */
static pour_status_t init_config(pour_control_t *ctl, const pour_control_config_t *c) {
  if (c->input_timeout_ms < 1u || c->plausible_theta_urad <= 0 || c->plausible_omega_urad_s <= 0 ||
      c->plausible_volume_sum <= 0 || c->restart_jump_max_urad <= 0) {
    return POUR_EINVAL;
  }
  if (pour_safety_init(&ctl->safety, &c->safety) != POUR_OK || !stop_config_ok(&c->stop) ||
      pour_experiment_validate(&c->experiment) != POUR_OK ||
      pour_estimator_init(&ctl->estimator, &c->sensors) != POUR_OK ||
      pour_supervisor_init(&ctl->supervisor, &c->supervisor, c->safety.theta_min_urad, c->safety.theta_max_urad) !=
          POUR_OK) {
    return POUR_EINVAL;
  }
  if (c->safe_torque > c->safety.tau_limit || c->safe_torque < -c->safety.tau_limit) {
    return POUR_EINVAL;
  }
  return POUR_OK;
}

static void start(pour_control_t *ctl, const pour_control_config_t *c, uint16_t decision_period_ms) {
  ctl->config = *c;
  ctl->decision_period_ms = decision_period_ms;
  ctl->mode = POUR_MODE_IDLE;
  ctl->faults = 0u;
  ctl->tick = 0u;
  ctl->refused = 0u;
  ctl->check_restart = false;
  ctl->have_trusted = false;
  ctl->experiment_asked = false;
  ctl->experiment_answer = (uint8_t)POUR_CONTROL_EXPERIMENT_NO_ANSWER;
  ctl->drive_untrusted = false;
  start_afresh(ctl); /* the envelope at zero, as pour_safety_init left it: the motor has no current yet */
}

pour_status_t pour_control_init(pour_control_t *ctl, const pour_control_config_t *config,
                                const pour_policy_weights_t *weights) {
  if (ctl == NULL || config == NULL) {
    return POUR_EINVAL;
  }
  pour_status_t status = init_config(ctl, config);
  if (status != POUR_OK) {
    return status;
  }
  status = pour_policy_init(&ctl->policy, weights, config->policy_mode, config->seed);
  if (status != POUR_OK) {
    return status;
  }
  ctl->policy_rng0 = ctl->policy.rng;
  start(ctl, config, weights->decision_period_ms);
  return POUR_OK;
}

pour_status_t pour_control_init_external(pour_control_t *ctl, const pour_control_config_t *config,
                                         uint16_t decision_period_ms) {
  if (ctl == NULL || config == NULL || decision_period_ms < 1u) {
    return POUR_EINVAL;
  }
  const pour_status_t status = init_config(ctl, config);
  if (status != POUR_OK) {
    return status;
  }
  ctl->policy.weights = NULL;
  ctl->policy.rng = ctl->policy_rng0 = 0u; /* no policy: its PRNG unused */
  start(ctl, config, decision_period_ms);
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

/* Toward the safe torque (zero where it would drive further past an angle limit): at once when that is
 * less torque, else through the slew limit, so that no transition steps the command away from zero. */
static q15_t hold_safe(pour_control_t *ctl) {
  const pour_safety_config_t *sc = &ctl->config.safety;
  const int32_t theta = ctl->state.theta_urad;
  q15_t torque = ctl->config.safe_torque;
  if ((torque > 0 && theta >= sc->theta_max_urad) || (torque < 0 && theta <= sc->theta_min_urad)) {
    torque = 0;
  }
  const q15_t now = ctl->safety.torque;
  if ((now > 0 && theta >= sc->theta_max_urad) || (now < 0 && theta <= sc->theta_min_urad)) {
    pour_safety_force(&ctl->safety, 0); /* no torque past an angle limit, not even on the way: zero first */
    return 0;
  }
  return pour_safety_hold(&ctl->safety, torque);
}

/* FAULT with the active stop under way (it has acted, and is not over). */
static bool stop_running(const pour_control_t *ctl) {
  return ctl->mode == POUR_MODE_FAULT && ctl->stop_ms > 0u && !ctl->stopped;
}

static void count_refused(pour_control_t *ctl) {
  if (ctl->refused != UINT32_MAX) {
    ctl->refused++;
  }
}

/* A restart of an axis the brake holds: its first sample must find the bucket where it was last seen. */
static void expect_held_angle(pour_control_t *ctl) {
  if (ctl->mode == POUR_MODE_FAULT && ctl->stopped && ctl->have_trusted) {
    ctl->check_restart = true;
  }
}

/* The active stop's request: a speed reference that returns toward upright at a bounded speed, tracked by
 * a bounded proportional torque. Units: θ [µrad], θ̇ [µrad/s]; torque Q15. */
static q15_t stop_request(const pour_stop_config_t *c, const pour_state_t *s) {
  int64_t ref = -(int64_t)c->return_gain_per_s * s->theta_urad;
  ref = ref > c->return_speed_urad_s ? c->return_speed_urad_s
                                      : (ref < -c->return_speed_urad_s ? -c->return_speed_urad_s : ref);
  /* err [µrad/s] * Q15 per rad/s / 1e6; |err| < 2^32, |gain| < 2^15: int64 holds it. */
  const int64_t t = ((ref - s->omega_urad_s) * c->gain) / 1000000;
  return (q15_t)(t > c->torque_max ? c->torque_max : (t < -c->torque_max ? -c->torque_max : t));
}

static bool at_rest(const pour_stop_config_t *c, const pour_state_t *s) {
  return s->theta_urad <= c->rest_theta_urad && s->theta_urad >= -c->rest_theta_urad &&
         s->omega_urad_s <= c->rest_omega_urad_s && s->omega_urad_s >= -c->rest_omega_urad_s;
}

/* FAULT: an active stop while the fault allows it and fresh states keep coming; false once it is over (or
 * never could act): then the safe torque with the brake engaged and the power cut. */
static bool stop_active(pour_control_t *ctl) {
  const pour_stop_config_t *c = &ctl->config.stop;
  if (!ctl->stopped) {
    const uint16_t active = (uint16_t)(POUR_FAULT_ACTIVE_STOP | (ctl->drive_untrusted ? 0u : POUR_FAULT_DRIVE));
    const bool can_act = (ctl->faults & (uint16_t)~active) == 0u &&
                         ctl->ms_since_fresh <= ctl->config.input_timeout_ms && ctl->stop_ms < c->timeout_ms;
    if (!can_act || at_rest(c, &ctl->state)) {
      ctl->stopped = true;
    } else {
      ctl->stop_ms++;
    }
  }
  return !ctl->stopped;
}

static void fill_output(const pour_control_t *ctl, q15_t torque, pour_control_output_t *out) {
  out->torque = torque;
  out->action = ctl->eval.action; /* out->probs: pour_control_probs, on demand */
  out->mode = (uint8_t)ctl->mode;
  out->faults = ctl->faults;
  out->limits = ctl->safety.active;
  out->tick = ctl->tick;
  out->refused = ctl->refused;
  out->brake = ctl->mode != POUR_MODE_RUN;
  out->power = ctl->mode == POUR_MODE_RUN;
}

/* The request of pour_control_experiment (one is pending), after this tick's Stop and Reset (so that a Stop and a start
 * in one tick start the experiment). */
static void take_experiment_request(pour_control_t *ctl) {
  ctl->experiment_asked = false;
  uint8_t answer = (uint8_t)POUR_CONTROL_EXPERIMENT_ACCEPTED;
  if (ctl->experiment_kind == (uint8_t)POUR_EXPERIMENT_NONE || ctl->experiment_kind > POUR_EXPERIMENT_KIND_MAX) {
    answer = (uint8_t)POUR_CONTROL_EXPERIMENT_REFUSED_KIND;
  } else if (ctl->mode == POUR_MODE_RUN) {
    answer = (uint8_t)POUR_CONTROL_EXPERIMENT_REFUSED_RUNNING;
  } else if (ctl->mode == POUR_MODE_FAULT) {
    answer = (uint8_t)POUR_CONTROL_EXPERIMENT_REFUSED_FAULT;
  } else {
    pour_experiment_start(&ctl->experiment, &ctl->config.experiment, ctl->experiment_kind);
    pour_estimator_expect_empty(&ctl->estimator, ctl->experiment_kind == (uint8_t)POUR_EXPERIMENT_IDENTIFY);
    ctl->held = false;
  }
  if (answer != (uint8_t)POUR_CONTROL_EXPERIMENT_ACCEPTED) {
    count_refused(ctl);
  }
  ctl->experiment_answer = answer;
}

/* An armed experiment (kind not NONE) runs in RUN: its request every tick, in place of any decision; its end (or a Stop)
 * leaves the axis held in IDLE; a fault ends it as it ends any run. */
static void experiment_tick(pour_control_t *ctl) {
  pour_experiment_t *e = &ctl->experiment;
  if (ctl->mode != POUR_MODE_RUN) {
    if (ctl->mode == POUR_MODE_FAULT || e->started) {
      ctl->held = ctl->mode == POUR_MODE_IDLE;
      end_experiment(ctl);
    }
    return;
  }
  bool ended = false;
  ctl->request = pour_experiment_step(e, &ctl->state, &ended);
  ctl->eval.action = e->phase;
  ctl->decision_due = false;
  ctl->probs_pending = false;
  if (ended) {
    ctl->mode = POUR_MODE_IDLE;
    ctl->held = true;
    end_experiment(ctl);
  }
}

/* The stages' one implementation, inlined into pour_control_step so that the MCU's tick pays no calls
 * between them (its image keeps only the step: --gc-sections drops the public stage entry points). */
#if defined(__GNUC__)
#define STAGE static inline __attribute__((always_inline))
#else
#define STAGE static inline
#endif

STAGE bool update_stage(pour_control_t *ctl, const pour_control_input_t *in) {
  ctl->tick++;
  ctl->decision_due = false;
  if (in->estop) {
    ctl->mode = POUR_MODE_ESTOP;
    ctl->faults |= POUR_FAULT_ESTOP;
    ctl->stopped = true; /* after the release: brake and power cut until a clear */
    end_experiment(ctl);
    if (ctl->experiment_asked) {
      ctl->experiment_asked = false;
      ctl->experiment_answer = (uint8_t)POUR_CONTROL_EXPERIMENT_REFUSED_ESTOP;
      count_refused(ctl);
    }
    if (in->stop) {
      count_refused(ctl);
    }
    if (in->reset) {
      count_refused(ctl);
    }
    return false;
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
  if (in->drive_faults != 0u) {
    /* The drive's own fault, a level as the link's: its word names it on the bus (DriveTelemetry). */
    ctl->faults |= POUR_FAULT_DRIVE;
    ctl->drive_untrusted = ctl->drive_untrusted || !in->drive_trusted;
    ctl->mode = POUR_MODE_FAULT;
  }
  /* A clear or a restart in the middle of the active stop would drop a torque that is braking the bucket
   * and start the speed estimate from rest while it turns: both wait until the stop is over. A clear in a
   * tick whose link or drive fault is still asserted is refused too: it would release the brake toward a
   * transport or a drive that is still faulted (the level latches its bit again, but only after a first
   * sample had already started a run). */
  const bool stopping = stop_running(ctl);
  if (in->clear_faults && (stopping || in->link_fault || in->drive_faults != 0u)) {
    count_refused(ctl);
  } else if (in->clear_faults && ctl->mode == POUR_MODE_FAULT) {
    expect_held_angle(ctl);
    /* Back to IDLE: RUN (and the timeout) start again only with the next fresh state, from the safe
     * torque the envelope holds now, through the slew limit. */
    ctl->faults = 0u;
    ctl->mode = POUR_MODE_IDLE;
    ctl->ms_since_fresh = 0u;
    ctl->stop_ms = 0u;
    ctl->stopped = false;
    ctl->drive_untrusted = false;
  }
  if (in->stop) {
    if (ctl->mode == POUR_MODE_RUN) {
      /* The run ends held: with samples still coming, a new run would start at the next one (the virtual
       * board's finding, docs/virtual-board.md). Only a Reset arms the next run (docs/can.md: Stop + Reset). */
      ctl->mode = POUR_MODE_IDLE;
      ctl->held = true;
    } else {
      count_refused(ctl); /* nothing to end */
    }
  }
  if (in->reset) {
    /* A restart under a running policy would drop the torque that holds the bucket: refused, as during the
     * active stop. */
    if ((ctl->mode == POUR_MODE_IDLE || ctl->mode == POUR_MODE_FAULT) && !stopping) {
      expect_held_angle(ctl);
      start_afresh(ctl);
      /* In FAULT the run's state restarts, but the brake keeps holding: only a clear releases it. */
      ctl->stopped = ctl->mode == POUR_MODE_FAULT;
    } else {
      count_refused(ctl);
    }
  }

  /* The experiment's two hooks are tested here, not in them: the policy's tick pays no calls for them. */
  if (ctl->experiment_asked) {
    take_experiment_request(ctl);
  }

  bool fresh = false;
  if (in->sensors_fresh && ctl->mode == POUR_MODE_IDLE) {
    /* A run's estimate starts from its own first sample: θ̇ from rest, m0 from the liquid as it is now. */
    pour_estimator_reset(&ctl->estimator);
  }
  if (in->sensors_fresh && pour_supervisor_accept(&ctl->supervisor, in->sensors.seq)) {
    pour_state_t state;
    bool ok = pour_estimator_update(&ctl->estimator, &in->sensors, &state) && plausible(&ctl->config, &state);
    if (ok && ctl->check_restart) {
      /* The restarted estimator would take any angle: the brake held the bucket, so it must be where it was. */
      const int64_t moved = (int64_t)state.theta_urad - ctl->trusted_theta_urad;
      ok = moved <= ctl->config.restart_jump_max_urad && moved >= -(int64_t)ctl->config.restart_jump_max_urad;
    }
    if (!ok) {
      ctl->faults |= POUR_FAULT_BAD_INPUT;
      ctl->mode = POUR_MODE_FAULT;
    } else {
      ctl->check_restart = false;
      ctl->have_trusted = true;
      ctl->trusted_theta_urad = state.theta_urad;
      ctl->state = state;
      ctl->ms_since_fresh = 0u;
      fresh = true;
    }
  }
  if (!fresh) {
    if (ctl->ms_since_fresh != UINT32_MAX) {
      ctl->ms_since_fresh++;
    }
    if (ctl->mode == POUR_MODE_RUN && ctl->ms_since_fresh > ctl->config.input_timeout_ms) {
      ctl->faults |= POUR_FAULT_STALE_INPUT;
      if (ctl->supervisor.seq_repeats > 0u) {
        ctl->faults |= POUR_FAULT_SEQ; /* samples came, but the same one again: a frozen sender */
      }
      ctl->mode = POUR_MODE_FAULT;
    }
  }

  if (ctl->mode == POUR_MODE_IDLE && fresh && !ctl->held) {
    ctl->mode = POUR_MODE_RUN;
    ctl->ms_to_decision = 0u;
    pour_supervisor_restart(&ctl->supervisor); /* the new run's windows start empty */
  }
  if (ctl->mode == POUR_MODE_RUN) {
    const uint16_t proven = pour_supervisor_step(&ctl->supervisor, &ctl->state, fresh);
    if (proven != 0u) {
      ctl->faults |= proven;
      ctl->mode = POUR_MODE_FAULT;
    }
  }
  if (ctl->mode == POUR_MODE_RUN) {
    ctl->decision_due = ctl->ms_to_decision == 0u;
    if (ctl->decision_due) {
      ctl->ms_to_decision = ctl->decision_period_ms;
    }
    ctl->ms_to_decision--;
  }
  if (ctl->experiment.kind != (uint8_t)POUR_EXPERIMENT_NONE) {
    experiment_tick(ctl);
  }
  return ctl->decision_due;
}

const pour_state_t *pour_control_state(const pour_control_t *ctl) { return &ctl->state; }

void pour_control_hold(pour_control_t *ctl) {
  if (ctl->mode == POUR_MODE_IDLE) {
    ctl->held = true;
  }
}

bool pour_control_held(const pour_control_t *ctl) { return ctl->held; }

bool pour_control_clear_acceptable(const pour_control_t *ctl, const pour_control_input_t *in) {
  if (in->estop || in->link_fault) {
    return false;
  }
  /* The e-stop released this tick turns ESTOP into FAULT with its stop over (update_stage). */
  return ctl->mode == POUR_MODE_ESTOP || (ctl->mode == POUR_MODE_FAULT && !stop_running(ctl));
}

STAGE void decide_stage(pour_control_t *ctl) {
  const pour_policy_weights_t *w = ctl->policy.weights;
  if (w == NULL) {
    return; /* an external controller: its request stays */
  }
  pour_obs_quantize(&w->norm, &ctl->state, &ctl->obs);
  /* A greedy decision needs only the argmax of the logits: no tick computes its probabilities (telemetry);
   * pour_control_probs does, for a caller that reports them. */
  ctl->probs_pending = !pour_policy_decide(&ctl->policy, &ctl->obs, &ctl->eval);
  ctl->request = w->action_levels[ctl->eval.action];
}

void pour_control_experiment(pour_control_t *ctl, uint8_t kind) {
  ctl->experiment_asked = true;
  ctl->experiment_kind = kind;
}

uint8_t pour_control_experiment_answer(pour_control_t *ctl) {
  const uint8_t a = ctl->experiment_answer;
  ctl->experiment_answer = (uint8_t)POUR_CONTROL_EXPERIMENT_NO_ANSWER;
  return a;
}

void pour_control_request(pour_control_t *ctl, uint8_t action, q15_t torque) {
  ctl->eval.action = action;
  ctl->request = torque;
}

STAGE void shape_stage(pour_control_t *ctl, pour_control_output_t *out) {
  if (ctl->mode == POUR_MODE_ESTOP) {
    pour_safety_force(&ctl->safety, 0);
    fill_output(ctl, 0, out);
    return;
  }
  const bool run = ctl->mode == POUR_MODE_RUN;
  const bool stopping = ctl->mode == POUR_MODE_FAULT && stop_active(ctl);
  if (!run && !stopping) {
    fill_output(ctl, hold_safe(ctl), out); /* IDLE, and FAULT once the stop is over */
    return;
  }
  /* The one place a request becomes a command: the decision's in RUN, the stop's in FAULT; neither ever
   * steps the torque by more than the slew limit. */
  const q15_t request = run ? ctl->request : stop_request(&ctl->config.stop, &ctl->state);
  const q15_t torque = pour_safety_apply(&ctl->safety, request, ctl->state.theta_urad, ctl->state.omega_urad_s);
  fill_output(ctl, torque, out);
  if (run) {
    pour_supervisor_record(&ctl->supervisor, &ctl->state, torque);
  } else {
    out->brake = false; /* the active stop drives the motor */
    out->power = true;
  }
}

void pour_control_probs(pour_control_t *ctl, pour_control_output_t *out) {
  if (ctl->probs_pending) {
    pour_policy_fill_probs(&ctl->policy, &ctl->eval); /* the latest greedy decision's, once */
    ctl->probs_pending = false;
  }
  memcpy(out->probs, ctl->eval.probs, sizeof out->probs);
}

bool pour_control_update(pour_control_t *ctl, const pour_control_input_t *in) { return update_stage(ctl, in); }

void pour_control_decide(pour_control_t *ctl) { decide_stage(ctl); }

void pour_control_shape(pour_control_t *ctl, pour_control_output_t *out) { shape_stage(ctl, out); }

/* Not inlined into a port's tick: the step stays one function in the image, so that a profiler finds it by its
 * symbol (virtual_board --profile; docs/virtual-board.md, "Cycle counts"). One call costs a few instructions. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
void pour_control_step(pour_control_t *ctl, const pour_control_input_t *in, pour_control_output_t *out) {
  if (update_stage(ctl, in)) {
    decide_stage(ctl);
  }
  shape_stage(ctl, out);
}
