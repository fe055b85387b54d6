/* SPDX-License-Identifier: MIT */
/* The identification experiments the controller runs itself (docs/bench.md, "System identification"): a
 * scripted torque request every tick, from the estimated state, within a stated angle range. The control
 * step puts the request through the same envelope and supervisor as a policy's (pour_control_experiment).
 * Pure: no I/O, no float. */
#ifndef POUR_EXPERIMENT_H
#define POUR_EXPERIMENT_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"
#include "pour/obs.h"

typedef enum {
  POUR_EXPERIMENT_NONE = 0,
  POUR_EXPERIMENT_IDENTIFY = 1, /* bucket empty: torque steps, a chirp, a sweep, about a hold angle */
  POUR_EXPERIMENT_TILT = 2      /* with water: a slow tilt to an angle and back */
} pour_experiment_kind_t;
#define POUR_EXPERIMENT_KIND_MAX 2u

/* What the experiment is doing: the Torque frame's Action while it runs, and after it ends (IDLE, held)
 * how it ended. */
typedef enum {
  POUR_EXPERIMENT_PHASE_RAMP = 1,   /* identify: to the hold angle */
  POUR_EXPERIMENT_PHASE_STEPS = 2,  /* identify: torque steps about it, a binary sequence on them */
  POUR_EXPERIMENT_PHASE_CHIRP = 3,  /* identify: a chirp about it */
  POUR_EXPERIMENT_PHASE_BACK = 4,   /* identify: back to the start angle */
  POUR_EXPERIMENT_PHASE_TILT = 5,   /* tilt: up at the tilt speed */
  POUR_EXPERIMENT_PHASE_DWELL = 6,  /* tilt: held at the top */
  POUR_EXPERIMENT_PHASE_RETURN = 7, /* tilt: back to the start angle */
  POUR_EXPERIMENT_PHASE_DONE = 8,   /* ended: the script ran to its end */
  POUR_EXPERIMENT_PHASE_OUT_OF_RANGE = 9, /* ended: the angle left the range */
  POUR_EXPERIMENT_PHASE_SWEEP = 10       /* identify, after the chirp: a triangle about the hold angle at a
                                          * steady speed (viscous friction), then BACK */
} pour_experiment_phase_t;

/* Defaults: pour_experiment_default_config (docs/bench.md gives the reasons). Gains in torque Q15 (of
 * tau_max) per rad and per rad/s. */
typedef struct {
  int32_t hold_theta_urad;   /* identify: the hold angle [µrad], > 0 */
  int32_t range_urad;        /* identify: |θ - hold| beyond this ends it [µrad], >= hold (upright inside) */
  int32_t kp_per_rad;        /* identify: hold stiffness [Q15 / rad], > 0 */
  int32_t kd_per_rad_s;      /* identify: hold damping [Q15 / (rad/s)], >= 0 */
  q15_t step_torque;         /* identify: the steps' amplitude, Q15, > 0 */
  q15_t chirp_torque;        /* identify: the chirp's amplitude, Q15, > 0 */
  q15_t prbs_torque;         /* identify: a pseudo-random binary sequence on the steps, its amplitude, Q15, >= 0 */
  uint8_t prbs_bit_ms;       /* identify: ... one bit this long [ms], >= 1 */
  uint16_t chirp_f0_mhz;     /* identify: the chirp's start frequency [mHz], > 0 */
  uint16_t chirp_f1_mhz;     /* identify: ... and its end frequency [mHz], > f0, <= 50 Hz */
  int32_t tilt_theta_urad;   /* tilt: up to this angle [µrad], > 0 */
  int32_t tilt_speed_urad_s; /* tilt: at this speed [µrad/s], > 0 */
  int32_t tilt_margin_urad;  /* tilt: below -margin or above tilt + margin ends it [µrad], > 0 */
  int32_t tilt_kp_per_rad;   /* tilt: tracking stiffness [Q15 / rad], > 0 */
  int32_t tilt_kd_per_rad_s; /* tilt: tracking damping [Q15 / (rad/s)], >= 0 */
} pour_experiment_config_t;

typedef struct {
  pour_experiment_config_t config;
  uint8_t kind;            /* pour_experiment_kind_t; NONE: not running */
  uint8_t phase;           /* pour_experiment_phase_t */
  bool started;            /* the first state was taken (start angle) */
  uint32_t ms;             /* ticks since the first state [ms] */
  int32_t start_theta_urad; /* the angle it started from, and returns to [µrad] */
  uint32_t phase_turn;     /* the chirp's phase [2^-32 turn] */
  uint16_t lfsr;           /* the sequence's shift register (x^16 + x^14 + x^13 + x^11 + 1) */
} pour_experiment_t;

pour_experiment_config_t pour_experiment_default_config(void);

/* POUR_EINVAL for a config outside the ranges above. */
pour_status_t pour_experiment_validate(const pour_experiment_config_t *config);

/* Duration of an experiment from its first tick, at most [ms] (0 for NONE). */
uint32_t pour_experiment_duration_ms(const pour_experiment_config_t *config, uint8_t kind);

/* Arms kind (a validated config): the next pour_experiment_step takes the start angle. */
void pour_experiment_start(pour_experiment_t *e, const pour_experiment_config_t *config, uint8_t kind);

/* One tick on the estimated state: the torque request, Q15 (saturated at ±1). Sets *ended (and the phase
 * to DONE or OUT_OF_RANGE, the kind to NONE) when the script is over or the angle left the range; then the
 * request is 0. */
q15_t pour_experiment_step(pour_experiment_t *e, const pour_state_t *state, bool *ended);

#endif /* POUR_EXPERIMENT_H */
