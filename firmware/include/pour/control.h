/* SPDX-License-Identifier: MIT */
/* The 1 kHz control step: raw sensor samples in, torque out, inside the safety envelope. Pure: no I/O, no
 * float. */
#ifndef POUR_CONTROL_H
#define POUR_CONTROL_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/faults.h"
#include "pour/experiment.h"
#include "pour/fixed.h"
#include "pour/obs.h"
#include "pour/policy.h"
#include "pour/safety.h"
#include "pour/sensors.h"
#include "pour/supervisor.h"

/* Version of the firmware as the bus reports it (Identity.FwVersion): +1 with any change in behaviour a
 * host or a bench engineer must know of. 2: supervisor, controlled stop, explicit stop/reset, identity.
 * 3: raw sensor samples in (the estimator), the motion envelope (speed governor, acceleration ramp).
 * 4: parameters and calibration over CAN, the transitions of docs/safety.md (torque continuity, refusals).
 * 5: the drive (DRIVE fault, DriveTelemetry, calibration results), ExperimentStart.
 * 6: CalibrationResult's 5-bit Status (the interlock's refusals) and Stored in bits 5..7; the Crystal signal.
 * 7: parameters 28-30, the supervisor's tilt margin and overspeed limit and the estimator's jump limit.
 * 8: no run starts on its own: a Stop ends the run held, the board boots held (Heartbeat's Held) until a Reset.
 * It is the DBC's protocol number (VERSION "pour CAN protocol N"), which test_can_dbc pins. */
#define POUR_FIRMWARE_VERSION 8u

/* The controlled stop (docs/safety.md gives the reasons for the defaults). */
typedef struct {
  q15_t torque_max;             /* |stop torque| <= this, Q15, > 0 (then the envelope's clamp and slew) */
  int32_t return_speed_urad_s;  /* toward upright at no more than this [µrad/s], > 0 */
  uint16_t return_gain_per_s;   /* speed reference = -gain * θ [1/s], >= 1 */
  q15_t gain;                   /* torque per rad/s of speed error, Q15 per rad/s, > 0 */
  int32_t rest_theta_urad;      /* done when |θ| <= this ... [µrad], > 0 */
  int32_t rest_omega_urad_s;    /* ... and |θ̇| <= this [µrad/s], > 0 */
  uint16_t timeout_ms;          /* brake anyway after this long [ms], >= 1 */
} pour_stop_config_t;

typedef struct {
  pour_safety_config_t safety;
  pour_sensors_config_t sensors; /* the estimator: encoder bits, tracking loop, scale limits */
  uint16_t input_timeout_ms;   /* fresh sample required at least this often in RUN, >= 1 */
  q15_t safe_torque;           /* command in IDLE and FAULT, within the envelope, Q15 */
  pour_policy_mode_t policy_mode;
  uint32_t seed;               /* sampled mode's PRNG seed */
  /* A state estimated from a fresh sample outside these bounds is physically impossible: BAD_INPUT. */
  int32_t plausible_theta_urad;    /* |θ| <= this [µrad], > 0 */
  int32_t plausible_omega_urad_s;  /* |θ̇| <= this [µrad/s], > 0 */
  int32_t plausible_volume_sum;    /* V_rot + V_tgt + V_spill <= this, Q15 (32768 = all the liquid) */
  /* The first sample after a restart of an axis the brake held (a Reset or a clear in FAULT once the stop is
   * over) lies within this of the last trusted angle, or it is BAD_INPUT [µrad], > 0. */
  int32_t restart_jump_max_urad;
  pour_supervisor_config_t supervisor;
  pour_stop_config_t stop;
  pour_experiment_config_t experiment; /* the identification experiments (pour_control_experiment) */
} pour_control_config_t;

/* The answer to pour_control_experiment, given by the next update. */
typedef enum {
  POUR_CONTROL_EXPERIMENT_NO_ANSWER = 0,      /* nothing asked since the last answer was read */
  POUR_CONTROL_EXPERIMENT_ACCEPTED = 1,       /* armed: it runs from the next fresh sample on */
  POUR_CONTROL_EXPERIMENT_REFUSED_RUNNING = 2, /* asked for in RUN: Stop first */
  POUR_CONTROL_EXPERIMENT_REFUSED_ESTOP = 3,  /* asked for while the e-stop is asserted */
  POUR_CONTROL_EXPERIMENT_REFUSED_FAULT = 4,  /* asked for in FAULT: clear first */
  POUR_CONTROL_EXPERIMENT_REFUSED_KIND = 5    /* not a pour_experiment_kind_t that runs */
} pour_control_experiment_answer_t;

/* Inputs of one tick. */
typedef struct {
  bool sensors_fresh;     /* a new sensor sample arrived since the last tick */
  pour_sensors_t sensors; /* that sample, raw */
  bool estop;        /* e-stop line/frame asserted (level) */
  bool clear_faults; /* request to clear latched faults (acted on in FAULT once the active stop is over, and
                      * only while link_fault and drive_faults are clear in the same tick) */
  bool link_fault;   /* level: the transport's command watchdog has tripped; latches POUR_FAULT_LINK */
  bool stop;         /* one-shot: the host ends the run, RUN -> IDLE held (safe torque, brake) until a Reset */
  bool reset;        /* one-shot: start a new run from the power-on state; refused in RUN, ESTOP, active stop */
  uint16_t drive_faults; /* level: the drive's latched fault word (POUR_DRIVE_FAULT_*; 0: none, or no drive of
                          * its own); any bit latches POUR_FAULT_DRIVE */
  bool drive_trusted;    /* with drive_faults: the drive still follows a torque (the controlled stop runs); false:
                          * it does not (its phases are shorted), the stop is over at once */
} pour_control_input_t;

/* Outputs of one tick. */
typedef struct {
  q15_t torque;   /* command, fraction of tau_max Q15 */
  uint8_t action; /* index of the current policy action */
  q15_t probs[POUR_POLICY_MAX_ACTIONS]; /* probabilities of the latest decision, Q15: written only by
                                         * pour_control_probs (the step leaves them as they were) */
  uint8_t mode;   /* pour_mode_t */
  uint16_t faults; /* POUR_FAULT_* */
  uint8_t limits;  /* POUR_LIMIT_* active this tick */
  uint32_t tick;   /* ticks since init */
  uint32_t refused; /* Stop, Reset, clear and experiment requests refused so far (they changed nothing else) */
  bool brake;      /* engage the holding brake (IDLE, ESTOP, and FAULT once the stop is done) */
  bool power;      /* motor power stage enabled (RUN and an active stop only) */
} pour_control_output_t;

typedef struct {
  pour_control_config_t config;
  pour_policy_t policy;
  uint32_t policy_rng0;   /* the policy's PRNG state as init left it: a Reset puts it back */
  pour_safety_t safety;
  pour_mode_t mode;
  uint16_t faults;
  uint32_t tick;
  uint32_t ms_since_fresh;
  uint32_t ms_to_decision;
  pour_estimator_t estimator;
  pour_state_t state; /* state estimated from the latest fresh, plausible sample */
  pour_obs_t obs;
  pour_policy_eval_t eval;
  bool probs_pending;     /* the latest greedy decision's probabilities are not computed yet (pour_control_probs) */
  bool decision_due;      /* this tick's update found a decision due */
  uint16_t decision_period_ms; /* ticks between decisions in RUN */
  q15_t request;          /* the latest decision's torque request, Q15 (into the envelope every RUN tick) */
  pour_supervisor_t supervisor;
  uint32_t stop_ms;       /* ticks of the active stop so far */
  bool stopped;           /* the stop is over: brake and power cut until a clear */
  uint32_t refused;       /* Resets refused (RUN, ESTOP, the active stop), clears during the active stop, Stops
                           * outside RUN, experiments refused (pour_control_experiment_answer_t) */
  bool have_trusted;      /* a fresh, plausible sample was taken since init */
  int32_t trusted_theta_urad; /* the angle of the latest one: a restart of a held axis must find it again [µrad] */
  bool check_restart;     /* the next fresh sample is the first after a restart of a held axis */
  pour_experiment_t experiment; /* armed or running identification experiment (kind NONE: none) */
  bool experiment_asked;  /* a pour_control_experiment waits for the next update */
  uint8_t experiment_kind; /* ... of this kind */
  uint8_t experiment_answer; /* pour_control_experiment_answer_t of the latest request */
  bool held;              /* IDLE with no run armed: after a Stop, an experiment's end or pour_control_hold (a port's
                           * boot); the brake holds and no sample starts a run until a Reset (or an experiment) */
  bool drive_untrusted;   /* a drive fault since the last clear came with a drive that no longer follows a torque */
} pour_control_t;

/* Defaults: docs/safety.md lists them with their reasons. */
pour_control_config_t pour_control_default_config(void);

/* Validates config and weights once; the controller starts in IDLE at zero torque.
 * POUR_EINVAL for a bad config, else pour_policy_weights_validate's status. */
pour_status_t pour_control_init(pour_control_t *ctl, const pour_control_config_t *config,
                                const pour_policy_weights_t *weights);

/* As pour_control_init, for a controller whose decisions come from outside (pour_control_request: a float
 * policy, a baseline, an agent, a link) every decision_period_ms (>= 1) ticks of RUN; no policy of its own. */
pour_status_t pour_control_init_external(pour_control_t *ctl, const pour_control_config_t *config,
                                         uint16_t decision_period_ms);

/* The 1 kHz tick is three stages, one implementation for every caller:
 *   due = pour_control_update(ctl, in);          estimate and supervise
 *   if (due) pour_control_decide(ctl);           or pour_control_request(ctl, action, torque)
 *   pour_control_shape(ctl, out);                the envelope, the controlled stop, the outputs
 * pour_control_step is exactly that with the fixed-point policy. A decision stays in force until the next. */

/* Stage 1. Order: e-stop (ESTOP, whatever else the input says), link fault (FAULT), drive fault (FAULT), clear
 * request (refused while the stop is active, the link fault is set or the drive's word is not 0), stop,
 * reset, input (a seq that does not advance makes the sample not fresh; the estimator turns a fresh one into
 * the state, restarted in IDLE so that a run starts from its first sample; an implausible sample or state:
 * BAD_INPUT), timeout (STALE_INPUT, with SEQ if repeated samples were refused; armed in RUN only), IDLE ->
 * RUN on the first fresh sample unless held (pour_control_hold, a Stop), supervisor (RUN). Returns whether a
 * decision is due: in RUN, on its first tick and every decision period after. */
bool pour_control_update(pour_control_t *ctl, const pour_control_input_t *in);

/* No run starts on its own: in IDLE, the axis is held (brake engaged, the safe torque) and no fresh sample
 * starts a run until a Reset arms one (or an experiment is accepted). A port calls it after init, so that after
 * any reset of the MCU (power-on, watchdog, software, pin) a rig whose samples keep coming does not resume the
 * pour by itself (IEC 60204-1 §7.5, §9.2.5.4.1: no restart after a reset or a power restoration); a Stop in
 * RUN leaves the axis held the same way. Outside IDLE it does nothing (a fault's clear returns to IDLE with
 * the hold as it was). */
void pour_control_hold(pour_control_t *ctl);

/* Whether no run is armed (pour_control_hold, a Stop, an experiment's end): IDLE waits for a Reset; in FAULT a clear
 * leaves the axis so. */
bool pour_control_held(const pour_control_t *ctl);

/* Whether a ClearErrors with these inputs would be acted on, the drive's fault word aside: the e-stop
 * released, no link fault, the core in FAULT with its active stop over (or in ESTOP, the line released
 * now). A port with a drive of its own asks before its step, clears the drive first when this holds, and
 * gives the step the drive's word as it stands after that: pour_control_update refuses a clear while the
 * word (or the link fault) is set, so a clear never releases a drive that is still faulted. */
bool pour_control_clear_acceptable(const pour_control_t *ctl, const pour_control_input_t *in);

/* The state estimated from the latest fresh, plausible sample (read-only; zero before the first). */
const pour_state_t *pour_control_state(const pour_control_t *ctl);

/* Stage 2, on the MCU: the fixed-point policy decides on the estimated state; the request becomes its
 * action's level. Without a policy (pour_control_init_external) it does nothing. */
void pour_control_decide(pour_control_t *ctl);

/* Stage 2 from outside: the action index (telemetry) and the torque request [Q15 of tau_max]. */
void pour_control_request(pour_control_t *ctl, uint8_t action, q15_t torque);

/* Asks for an identification experiment (pour/experiment.h), answered by the next update: accepted in IDLE
 * (it runs from the next fresh sample, the decisions coming from it every tick through the envelope and
 * supervisor), refused in RUN, ESTOP and FAULT. It ends with the bucket held: at its end, on leaving its
 * angle range or on a Stop the core goes to IDLE with the brake engaged and stays there until a Reset or
 * another experiment (the Action output says how it ended: pour_experiment_phase_t); a fault or the e-stop
 * ends it as they end any run. */
void pour_control_experiment(pour_control_t *ctl, uint8_t kind);

/* The answer to the latest pour_control_experiment (pour_control_experiment_answer_t), once: NO_ANSWER
 * after it was read. */
uint8_t pour_control_experiment_answer(pour_control_t *ctl);

/* Stage 3: in RUN the request through the envelope (and recorded for the supervisor), in FAULT the
 * controlled stop, else the safe torque (zero in ESTOP). A clear never bypasses the envelope: RUN resumes
 * from the safe torque through the slew limit. Fills out; out->tick counts the ticks including this one. */
void pour_control_shape(pour_control_t *ctl, pour_control_output_t *out);

/* One 1 ms tick with the fixed-point policy: update, decide when due, shape. Never fails: problems show as
 * mode and fault bits in the output. It computes no softmax for a greedy policy (the argmax of the logits is
 * the decision) and leaves out->probs as they were: see pour_control_probs. */
void pour_control_step(pour_control_t *ctl, const pour_control_input_t *in, pour_control_output_t *out);

/* The latest decision's probabilities into out->probs (Q15, zero past n_actions; zero before the first decision
 * and for an external controller): a sampled decision's as drawn from, a greedy decision's computed here on the
 * first call after it (one softmax, ~500 instructions on the Cortex-M4), so that only a port that reports them
 * pays, and outside the tick's budget. */
void pour_control_probs(pour_control_t *ctl, pour_control_output_t *out);

#endif /* POUR_CONTROL_H */
