/* SPDX-License-Identifier: MIT */
/* An episode tick by tick, for the Gymnasium environment: the same tick driver and episode meter as
 * poursim_rollout and host_sim (host_sim/src/episode_run.hpp), with the decisions from outside. Each due
 * decision of the firmware's pipeline (pour_control_init_external with decision_period) takes the action and
 * the torque level given to the latest poursim_stepper_advance, as a request through the core's estimator,
 * supervisor, envelope and controlled stop. */
#ifndef POURSIM_STEPPER_H
#define POURSIM_STEPPER_H

#include <stddef.h>
#include <stdint.h>

#include "pour/obs.h" /* pour_state_t */
#include "poursim/poursim.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct poursim_stepper poursim_stepper_t;

/* A stepper on world (borrowed: it must outlive the stepper) rewarded by reward; NULL with err on a NULL
 * world, a reward out of range or decision_period < 1. */
poursim_stepper_t *poursim_stepper_create(poursim_world_t *world, const poursim_reward_t *reward,
                                          int decision_period, char *err, size_t err_len);
void poursim_stepper_destroy(poursim_stepper_t *s);

/* Resets the world to seed and starts a fresh core for the episode's drawn rig; the first sample goes into
 * the pipeline. POURSIM_OK, or the world's or the core's failure in err. */
int poursim_stepper_reset(poursim_stepper_t *s, uint32_t seed, char *err, size_t err_len);

/* ticks steps, each decision due meanwhile requesting action with level [fraction of tau_max, Q15 as the
 * firmware rounds]; *reward (may be NULL) = the steps' rewards summed; commands (may be NULL, else ticks
 * long) = the core's torque command of each step [Q15 of tau_max]. POURSIM_OK, or the failure in err. */
int poursim_stepper_advance(poursim_stepper_t *s, int action, double level, int ticks, double *reward,
                            int16_t *commands, char *err, size_t err_len);

/* The latest observation; the state the core estimated; its latched POUR_FAULT_* bits. */
void poursim_stepper_obs(const poursim_stepper_t *s, poursim_obs_t *obs);
void poursim_stepper_state(const poursim_stepper_t *s, pour_state_t *state);
int poursim_stepper_faults(const poursim_stepper_t *s);

/* The episode's figures so far (the meter's, as poursim_rollout reports them; n_decisions is 0). */
void poursim_stepper_episode(poursim_stepper_t *s, poursim_episode_t *episode);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_STEPPER_H */
