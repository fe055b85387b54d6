/* SPDX-License-Identifier: MIT */
/* The drive's self-calibration, one step per PWM period from the current-loop interrupt (as ODrive's and
 * moteus's run theirs), with the bucket empty:
 *  1. phase resistance along α and then along β: a DC voltage vector raised by an integrator until the test
 *     current flows, R = V/I averaged; the two axes must agree (an open phase shows as a disagreement);
 *  2. phase inductance: a square wave of ±l_test on top of the β vector, L = V·Ts / |Δi| averaged;
 *  3. an open-loop electrical turn forward, a dwell, and the turn back, at the β stage's voltage (the test
 *     current at standstill): the encoder's direction (the sign of the counts), the pole pairs
 *     (encoder_cpr / counts per electrical turn) and the electrical offset (the commanded angle less the
 *     encoder's, averaged over both sweeps so that the rotor's lag cancels).
 * The encoder's motion is watched every period: beyond motion_counts from where it started, the sequence
 * ends at once. Takes 3.1 s. Fixed point, no float, no malloc, no I/O. */
#ifndef POUR_MOTOR_CAL_H
#define POUR_MOTOR_CAL_H

#include <stdint.h>

#include "pour/fixed.h"

/* Plausible motors (the drive's configuration accepts the same): 10 mΩ .. 10 Ω, 10 µH .. 10 mH, 1 .. 32. */
#define POUR_MOTOR_R_MIN_UOHM 10000u
#define POUR_MOTOR_R_MAX_UOHM 10000000u
#define POUR_MOTOR_L_MIN_NH 10000u
#define POUR_MOTOR_L_MAX_NH 10000000u
#define POUR_MOTOR_POLE_PAIRS_MAX 32u

/* The sequence's durations [ms]. */
#define POUR_MOTOR_CAL_R_SETTLE_MS 300u  /* per axis: the integrator's time constant is R/20 Ω/s (14 ms here) */
#define POUR_MOTOR_CAL_R_MEASURE_MS 100u /* per axis, averaged */
#define POUR_MOTOR_CAL_L_MS 100u
#define POUR_MOTOR_CAL_SWEEP_MS 1000u    /* one electrical turn, each way */
#define POUR_MOTOR_CAL_DWELL_MS 200u     /* at the end of the forward turn, before its counts are read */

typedef enum {
  POUR_MOTOR_CAL_NONE = 0,       /* not run since the drive started */
  POUR_MOTOR_CAL_RUNNING = 1,
  POUR_MOTOR_CAL_OK = 2,         /* measured, in range, applied */
  POUR_MOTOR_CAL_RESISTANCE = 3, /* R out of range on an axis, or the two axes more than 20 % apart (an open
                                    phase: no current on one axis, or 3× the other's) */
  POUR_MOTOR_CAL_INDUCTANCE = 4, /* L out of range */
  POUR_MOTOR_CAL_NO_ENCODER = 5, /* the encoder counted less than half a pole pitch of the finest motor in a turn */
  POUR_MOTOR_CAL_POLE_PAIRS = 6, /* the counts of an electrical turn divide encoder_cpr into no pole-pair count */
  POUR_MOTOR_CAL_MOTION = 7,     /* the encoder moved beyond motion_counts: the sequence stopped there */
  POUR_MOTOR_CAL_ABORTED = 8     /* a fault, the e-stop or a stop ended it */
} pour_motor_cal_status_t;

typedef struct {
  uint32_t pwm_hz;        /* steps a second [Hz], 1,000 .. 40,000 */
  uint32_t i_base_ma;     /* current of Q15 1.0 [mA], <= 100,000 */
  uint32_t v_base_mv;     /* voltage of Q15 1.0 [mV], <= 100,000 */
  uint32_t current_ma;    /* test current [mA], 100 .. i_base/2 */
  uint32_t l_test_mv;     /* square-wave amplitude of the inductance stage [mV], 100 .. 10,000 */
  uint32_t encoder_cpr;   /* motor encoder counts a turn, a power of two, 256 .. 65536 */
  uint32_t motion_counts; /* largest encoder motion from the start [counts], at least an electrical turn of
                             the finest motor (encoder_cpr / POUR_MOTOR_POLE_PAIRS_MAX) */
} pour_motor_cal_config_t;

typedef struct {
  uint32_t r_phase_uohm;      /* phase resistance [µΩ] */
  uint32_t l_phase_nh;        /* phase inductance [nH] */
  uint32_t pole_pairs;
  int32_t encoder_direction;  /* +1: the count rises with the electrical angle; −1: it falls */
  uint16_t electrical_offset; /* electrical angle at encoder count 0, 65536 = 2π */
  uint32_t peak_counts;       /* largest |encoder motion| from the start seen [counts] */
} pour_motor_cal_result_t;

typedef struct {
  pour_motor_cal_config_t config;
  pour_motor_cal_result_t result;
  uint8_t stage;            /* the stage running (motor_cal.c) */
  uint32_t n;               /* periods into the stage */
  int32_t ki_q16;           /* the resistance integrator's gain per period, per-unit V per per-unit A, Q16 */
  int32_t i_test_q15, l_test_q15;
  int64_t v_q31;            /* the resistance stage's voltage, Q15 << 16 */
  int64_t v_sum, i_sum;     /* the axis's sums over its measuring window */
  uint64_t r_sum_uohm;      /* the two axes' resistances */
  int32_t v_hold_q15;       /* the β stage's voltage: the vector of the inductance stage and the sweeps */
  int32_t l_acc;            /* Σ sign·Δi over the inductance stage [Q15] */
  q15_t i_prev;
  uint16_t encoder_last;
  uint16_t encoder_start;   /* the count when the sequence started */
  int32_t counts;           /* encoder motion since the start [counts], unwrapped */
  int32_t counts_sweep;     /* the motion when the forward turn began */
  int64_t angle_sum, counts_sum; /* Σ commanded angle (unwrapped) and Σ counts over both sweeps */
  uint32_t sweep_n;
} pour_motor_cal_t;

/* Starts the sequence; encoder: the count now. POUR_EINVAL for a config outside its ranges. */
pour_status_t pour_motor_cal_init(pour_motor_cal_t *cal, const pour_motor_cal_config_t *config, uint16_t encoder);

/* One period: the measured α and β currents (Q15), the encoder's count, the largest voltage the bus gives
 * (Q15) → the voltage vector for the next period (*v_alpha, *v_beta, Q15). RUNNING while it goes on; then
 * OK (cal->result holds the results) or the reason it stopped (the voltage is then 0). */
pour_motor_cal_status_t pour_motor_cal_step(pour_motor_cal_t *cal, q15_t i_alpha, q15_t i_beta, uint16_t encoder,
                                            int32_t v_limit_q15, q15_t *v_alpha, q15_t *v_beta);

#endif /* POUR_MOTOR_CAL_H */
