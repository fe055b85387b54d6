/* example_weights_2.h — pour policy. Hand-made (pour.golden.hand_made_weights(2), benchmarks). DO NOT EDIT. */
#ifndef POUR_WEIGHTS_H
#define POUR_WEIGHTS_H
#include <stdint.h>
#define POUR_WEIGHTS_FORMAT 1
#define POUR_WEIGHTS_N_FEATURES 6 /* theta, omega, v_rotating, v_target, v_spill, bias */
#define POUR_WEIGHTS_N_ACTIONS 2
#define POUR_WEIGHTS_W_FRAC_BITS 11 /* int16 weights, Q4.11 */
#define POUR_WEIGHTS_DECISION_PERIOD_MS 10
#define POUR_WEIGHTS_THETA_MIN_URAD 0
#define POUR_WEIGHTS_THETA_MAX_URAD 2356194
#define POUR_WEIGHTS_OMEGA_MAX_URAD_S 4000000
#define POUR_WEIGHTS_TAU_MAX_MNM 40000
#define POUR_WEIGHTS_CONTENT_HASH 0x15b6dd0cu
static const int16_t pour_weights_w[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {14746, -14746},
    {16384, -16384},
    {-19661, 19661},
    {0, 0},
    {0, 0},
    {-13107, -3277}
};
static const int16_t pour_weights_action_levels_q15[POUR_WEIGHTS_N_ACTIONS] = {-32768, 32767};
#ifdef POUR_WEIGHTS_FLOAT_REFERENCE
static const float pour_weights_w_float[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {7.19999981f, -7.19999981f},
    {8.0f, -8.0f},
    {-9.60000038f, 9.60000038f},
    {-0.0f, 0.0f},
    {-0.0f, 0.0f},
    {-6.4000001f, -1.60000002f}
};
#endif
#endif
