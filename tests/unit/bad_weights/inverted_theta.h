/* inverted_theta.h — deliberately bad weights.h (theta max below theta min): the build must fail naming POUR_WEIGHTS_THETA_MAX_URAD. Hand-made. */
#ifndef POUR_WEIGHTS_H
#define POUR_WEIGHTS_H
#include <stdint.h>
#define POUR_WEIGHTS_FORMAT 1
#define POUR_WEIGHTS_N_FEATURES 6 /* theta, omega, v_rotating, v_target, v_spill, bias */
#define POUR_WEIGHTS_N_ACTIONS 11
#define POUR_WEIGHTS_W_FRAC_BITS 11 /* int16 weights, Q4.11 */
#define POUR_WEIGHTS_DECISION_PERIOD_MS 10
#define POUR_WEIGHTS_THETA_MIN_URAD 0
#define POUR_WEIGHTS_THETA_MAX_URAD -1
#define POUR_WEIGHTS_OMEGA_MAX_URAD_S 4000000
#define POUR_WEIGHTS_TAU_MAX_MNM 40000
#define POUR_WEIGHTS_CONTENT_HASH 0x007a16deu
static const int16_t pour_weights_w[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS] = {
    {14746, 11796, 8847, 5898, 2949, 0, -2949, -5898, -8847, -11796, -14746},
    {16384, 13107, 9830, 6554, 3277, 0, -3277, -6554, -9830, -13107, -16384},
    {-19661, -15729, -11796, -7864, -3932, 0, 3932, 7864, 11796, 15729, 19661},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {-13107, -9175, -5898, -3277, -1311, 0, 655, 655, 0, -1311, -3277}
};
static const int16_t pour_weights_action_levels_q15[POUR_WEIGHTS_N_ACTIONS] = {-32768, -26214, -19661, -13107, -6554, 0, 6554, 13107, 19661, 26214, 32767};
#endif
