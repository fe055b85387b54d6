/* example_weights.h — pour policy. Hand-made (pour.policy.golden.hand_made_weights(11), kept for tests). DO NOT EDIT. */
#ifndef POUR_WEIGHTS_H
#define POUR_WEIGHTS_H
#include <stdint.h>
#define POUR_WEIGHTS_FORMAT 1
#define POUR_WEIGHTS_N_FEATURES 6 /* theta, omega, v_rotating, v_target, v_spill, bias */
#define POUR_WEIGHTS_N_ACTIONS 11
#define POUR_WEIGHTS_W_FRAC_BITS 9 /* int16 weights, Q6.9 */
#define POUR_WEIGHTS_DECISION_PERIOD_MS 10
#define POUR_WEIGHTS_THETA_MIN_URAD 0
#define POUR_WEIGHTS_THETA_MAX_URAD 2356194
#define POUR_WEIGHTS_OMEGA_MAX_URAD_S 4000000
#define POUR_WEIGHTS_TAU_MAX_MNM 20000
#define POUR_WEIGHTS_CONTENT_HASH 0x09b1269bu
static const int16_t pour_weights_w[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {4096, 3277, 2458, 1638, 819, 0, -819, -1638, -2458, -3277, -4096},
    {16384, 13107, 9830, 655