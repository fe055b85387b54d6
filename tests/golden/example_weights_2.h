/* example_weights_2.h — pour policy. Hand-made (pour.policy.golden.hand_made_weights(2), benchmarks). DO NOT EDIT. */
#ifndef POUR_WEIGHTS_H
#define POUR_WEIGHTS_H
#include <stdint.h>
#define POUR_WEIGHTS_FORMAT 1
#define POUR_WEIGHTS_N_FEATURES 6 /* theta, omega, v_rotating, v_target, v_spill, bias */
#define POUR_WEIGHTS_N_ACTIONS 2
#define POUR_WEIGHTS_W_FRAC_BITS 9 /* int16 weights, Q6.9 */
#define POUR_WEIGHTS_DECISION_PERIOD_MS 10
#define POUR_WEIGHTS_THETA_MIN_URAD 0
#define POUR_WEIGHTS_THETA_MAX_URAD 2356194
#define POUR_WEIGHTS_OMEGA_MAX_URAD_S 4000000
#define POUR_WEIGHTS_TAU_MAX_MNM 20000
#define POUR_WEIGHTS_CONTENT_HASH 0x68d78c3cu
static const int16_t pour_weights_w[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {4096, -4096},
    {16384, -16384},
    {-3072, 3072},
    {2048, -2048},
    {0, 0},
    {-14746, 10650}
};
static const int16_t pour_weights_action_levels_q15[POUR_WEIGHTS_N_ACTIONS] = {-32768, 32767};
#ifdef POUR_WEIGHTS_FLOAT_REFERENCE
static const float pour_weights_w_float[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {8.0f, -8.0f},
    {32.0f, -32.0f},
    {-6.0f, 6.0f},
    {4.0f, -4.0f},
    {-0.0f, 0.0f},
    {-28.7999992f, 20.7999992f}
};
#endif
#endif
