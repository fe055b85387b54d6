/* SPDX-License-Identifier: MIT */
/* What the rig's sensors give the controller, and the estimator that turns it into the plant state the
 * policy and the supervisor use. On a rig: θ from an absolute encoder on the output shaft; θ̇ is estimated
 * here from θ (nothing on the rig measures it); the volumes from two load cells, one carrying the rotating
 * bucket and one under the target. Pure, fixed point, no I/O. */
#ifndef POUR_SENSORS_H
#define POUR_SENSORS_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"
#include "pour/obs.h"

/* One sample of the sensors, as it crosses the wire (LCM, CAN) or comes from the in-process simulator. */
typedef struct {
  uint32_t seq;             /* sample counter, +1 per tick at the source */
  uint32_t encoder;         /* output-shaft absolute encoder, raw single-turn count 0 .. 2^bits - 1;
                             * 0 = upright, counting up as the bucket tilts to pour (below upright wraps
                             * to just under 2^bits) */
  int32_t scale_rotating_g; /* load cell carrying the rotating bucket, tared with the bucket empty [g] */
  int32_t scale_target_g;   /* load cell under the target bucket, tared with it empty [g] */
} pour_sensors_t;

#define POUR_ENCODER_BITS_MIN 8u
#define POUR_ENCODER_BITS_MAX 24u
#define POUR_SCALE_LIMIT_G 32767 /* |scale limits| <= this: m0 < 2^16 keeps the volume divides in 32 bits */
#define POUR_ESTIMATOR_GAP_MAX 32u /* a seq gap is credited with at most this many ticks of prediction */

/* docs/safety.md gives the reason for every default. */
typedef struct {
  uint8_t encoder_bits;     /* counts per turn = 2^bits, POUR_ENCODER_BITS_MIN .. _MAX */
  uint16_t bandwidth_rad_s; /* tracking loop's natural frequency ωn (critically damped) [rad/s], 1 .. 1000 */
  int32_t scale_min_g;      /* a scale reading below this is implausible [g], >= -POUR_SCALE_LIMIT_G */
  int32_t scale_max_g;      /* ... or above this [g], > scale_min_g, <= POUR_SCALE_LIMIT_G */
  int32_t mass_min_g;       /* m0 = m_rot + m_tgt below this cannot be divided by [g], >= 1 */
  int32_t jump_max_urad;    /* an encoder reading farther than this · n² from the loop's prediction, n ticks
                             * after the last sample, is a jump no drive makes [µrad], 1 .. 10^6 */
} pour_sensors_config_t;

typedef struct {
  pour_sensors_config_t config;
  int32_t gain_theta_q24; /* 2 ωn T, Q8.24 (T = 1 ms) */
  int32_t gain_omega_q24; /* ωn² T², Q8.24 */
  bool started;           /* a sample was taken since init/reset: m0 and the loop's state are set */
  uint32_t last_seq;      /* seq of the last sample taken */
  int64_t theta_q16;      /* tracking loop's position θ̂ [µrad] Q16 */
  int64_t omega_q16;      /* tracking loop's speed ω̂ [µrad per tick] Q16 */
  int32_t m0_g;           /* all the liquid: m_rot + m_tgt of the first sample [g] */
  bool empty_ok;          /* an empty bucket is expected (pour_estimator_expect_empty) */
} pour_estimator_t;

/* Defaults for the bench rig (17-bit encoder, 80 Hz load cells of 30 kg, 10 L of soymilk). */
pour_sensors_config_t pour_sensors_default_config(void);

/* Validates config (POUR_EINVAL otherwise) and starts the estimator reset. */
pour_status_t pour_estimator_init(pour_estimator_t *est, const pour_sensors_config_t *config);

/* Forgets the loop's state and m0: the next plausible sample starts them (θ̇ = 0 there). */
void pour_estimator_reset(pour_estimator_t *est);

/* One sample -> state: θ [µrad] from the encoder count (rounded, sign-symmetric; counts above 2^(bits-1)
 * are below upright), θ̇ [µrad/s] = the tracking loop's advance over the tick (ω̂ + 2 ωn e; the loop coasts
 * over a seq gap, 1 .. GAP_MAX ticks),
 * V_rot = m_rot/m0, V_tgt = m_tgt/m0 in Q15, each rounded and clipped to [0, 32767], V_spill = 1 - V_rot -
 * V_tgt clipped to [0, 32767]. false: an implausible sample (encoder count >= 2^bits, a scale outside its
 * limits, m0 too small unless an empty bucket is expected, θ farther from the loop's prediction than jump_max · n²); then neither the
 * estimator nor *state changes. */
bool pour_estimator_update(pour_estimator_t *est, const pour_sensors_t *sample, pour_state_t *state);

/* empty: the bucket is empty on purpose (the identify experiment, pour/experiment.h), so an m0 below
 * mass_min_g is no fault: the volumes are then all 0. Kept across pour_estimator_reset; off at init. */
void pour_estimator_expect_empty(pour_estimator_t *est, bool empty);

/* θ [µrad] of a raw count, as the estimator computes it (bits within POUR_ENCODER_BITS_MIN .. _MAX). */
int32_t pour_sensors_theta_urad(uint32_t count, uint8_t bits);

#endif /* POUR_SENSORS_H */
