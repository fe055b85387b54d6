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
    {16384, 13107, 9830, 6554, 3277, 0, -3277, -6554, -9830, -13107, -16384},
    {-3072, -2458, -1843, -1229, -614, 0, 614, 1229, 1843, 2458, 3072},
    {2048, 1638, 1229, 819, 410, 0, -410, -819, -1229, -1638, -2048},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {-14746, -11469, -8356, -5407, -2621, 0, 2458, 4751, 6881, 8847, 10650}
};
static const int16_t pour_weights_action_levels_q15[POUR_WEIGHTS_N_ACTIONS] = {-32768, -26214, -19661, -13107, -6554, 0, 6554, 13107, 19661, 26214, 32767};
#ifdef POUR_WEIGHTS_FLOAT_REFERENCE
static const float pour_weights_w_float[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {8.0f, 6.4000001f, 4.80000019f, 3.20000005f, 1.60000002f, -0.0f, -1.60000002f, -3.20000005f, -4.80000019f, -6.4000001f, -8.0f},
    {32.0f, 25.6000004f, 19.2000008f, 12.8000002f, 6.4000001f, -0.0f, -6.4000001f, -12.8000002f, -19.2000008f, -25.6000004f, -32.0f},
    {-6.0f, -4.80000019f, -3.5999999f, -2.4000001f, -1.20000005f, 0.0f, 1.20000005f, 2.4000001f, 3.5999999f, 4.80000019f, 6.0f},
    {4.0f, 3.20000005f, 2.4000001f, 1.60000002f, 0.800000012f, -0.0f, -0.800000012f, -1.60000002f, -2.4000001f, -3.20000005f, -4.0f},
    {-0.0f, -0.0f, -0.0f, -0.0f, -0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f},
    {-28.7999992f, -22.3999996f, -16.3199997f, -10.5600004f, -5.11999989f, 0.0f, 4.80000019f, 9.27999973f, 13.4399996f, 17.2800007f, 20.7999992f}
};
#endif
#endif
int pour_extra;
