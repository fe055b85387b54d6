/* SPDX-License-Identifier: MIT */
/* Plant state as the controller receives it, and its quantisation into the policy's observation. */
#ifndef POUR_OBS_H
#define POUR_OBS_H

#include <stdint.h>

#include "pour/fixed.h"

#define POUR_OBS_N 5 /* θ, θ̇, V_rotating, V_target, V_spill */

/* One sample of the plant, as it crosses the wire (LCM, CAN) or comes from the in-process simulator. */
typedef struct {
  uint32_t seq;          /* sample counter, increments by one per tick at the source */
  int32_t theta_urad;    /* bucket tilt [µrad], 0 = upright, positive pours */
  int32_t omega_urad_s;  /* tilt rate [µrad/s] */
  q15_t v_rotating;      /* liquid fraction in the rotating bucket [0, 1) Q15 */
  q15_t v_target;        /* liquid fraction in the target bucket [0, 1) Q15 */
  q15_t v_spill;         /* liquid fraction spilled [0, 1) Q15 */
} pour_state_t;

/* Normalisation ranges, from weights.h (the policy was trained with them). */
typedef struct {
  int32_t theta_min_urad;   /* θ that maps to 0 [µrad] */
  int32_t theta_max_urad;   /* θ that maps to 1 [µrad], > theta_min_urad */
  int32_t omega_max_urad_s; /* θ̇ in [-max, +max] maps to [0, 1] [µrad/s], > 0 */
} pour_obs_norm_t;

/* Normalised observation, each element in [0, 1) Q15 (never negative). */
typedef struct {
  q15_t x[POUR_OBS_N];
} pour_obs_t;

/* Checks a normalisation (ranges positive and not so wide that the scaling overflows). */
pour_status_t pour_obs_norm_validate(const pour_obs_norm_t *norm);

/* Quantises a state into the observation: round to nearest, then saturate to [0, 32767]. */
void pour_obs_quantize(const pour_obs_norm_t *norm, const pour_state_t *state, pour_obs_t *obs);

#endif /* POUR_OBS_H */
