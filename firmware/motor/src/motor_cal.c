/* SPDX-License-Identifier: MIT */
#include "pour/motor_cal.h"

#include <string.h>

#include "pour/foc.h"

/* The resistance stage's integrator: dV/dt = 20 V/(A·s) × (I_test − I). Its time constant R/20 Ω/s is 14 ms
 * on the rig's motor and 0.5 s on a 10 Ω one; an open phase drives it to the bus's limit in a few 100 ms. */
#define R_KI_V_PER_AS 20u
#define BETA_ANGLE 16384 /* the β axis, where the sweeps begin and end */

enum { ST_R_ALPHA, ST_R_BETA, ST_L, ST_FORWARD, ST_DWELL, ST_BACK };

static uint32_t periods(const pour_motor_cal_t *cal, uint32_t ms) { return ms * cal->config.pwm_hz / 1000u; }
static int32_t abs_i32(int32_t x) { return x < 0 ? -x : x; }
static int32_t clamp_i32(int32_t x, int32_t lo, int32_t hi) { return x < lo ? lo : (x > hi ? hi : x); }

pour_status_t pour_motor_cal_init(pour_motor_cal_t *cal, const pour_motor_cal_config_t *c, uint16_t encoder) {
  if (cal == NULL || c == NULL || c->pwm_hz < 1000u || c->pwm_hz > 40000u || c->i_base_ma == 0u ||
      c->i_base_ma > 100000u || c->v_base_mv == 0u || c->v_base_mv > 100000u || c->current_ma < 100u || c->current_ma > c->i_base_ma / 2u || c->l_test_mv < 100u ||
      c->l_test_mv > 10000u || c->l_test_mv > c->v_base_mv / 2u || c->encoder_cpr < 256u || c->encoder_cpr > 65536u ||
      (c->encoder_cpr & (c->encoder_cpr - 1u)) != 0u || c->motion_counts < c->encoder_cpr / POUR_MOTOR_POLE_PAIRS_MAX)
    return POUR_EINVAL;
  memset(cal, 0, sizeof *cal);
  cal->config = *c;
  const uint64_t ki = ((uint64_t)R_KI_V_PER_AS * 65536u * c->i_base_ma + (uint64_t)c->v_base_mv * c->pwm_hz / 2u) /
                      ((uint64_t)c->v_base_mv * c->pwm_hz);
  cal->ki_q16 = (int32_t)(ki > 0u ? ki : 1u);
  cal->i_test_q15 = (int32_t)(((uint64_t)c->current_ma * 32768u + c->i_base_ma / 2u) / c->i_base_ma);
  cal->l_test_q15 = (int32_t)(((uint64_t)c->l_test_mv * 32768u + c->v_base_mv / 2u) / c->v_base_mv);
  cal->encoder_last = cal->encoder_start = encoder;
  cal->stage = ST_R_ALPHA;
  return POUR_OK;
}

/* The resistance stage on one axis: the integrator's voltage, and at the end of the window R = ΣV/ΣI in µΩ
 * (V/I per-unit × v_base/i_base Ω). Returns RUNNING, or the stage's outcome once its window is over. */
static pour_motor_cal_status_t resistance(pour_motor_cal_t *cal, q15_t i, int32_t v_limit, int32_t *v) {
  const pour_motor_cal_config_t *c = &cal->config;
  cal->v_q31 += (int64_t)cal->ki_q16 * (cal->i_test_q15 - i);
  const int64_t top = (int64_t)v_limit << 16;
  if (cal->v_q31 > top) cal->v_q31 = top;
  if (cal->v_q31 < 0) cal->v_q31 = 0;
  *v = (int32_t)((cal->v_q31 + (1 << 15)) >> 16);
  const uint32_t settle = periods(cal, POUR_MOTOR_CAL_R_SETTLE_MS), window = periods(cal, POUR_MOTOR_CAL_R_MEASURE_MS);
  if (cal->n >= settle) {
    cal->v_sum += *v;
    cal->i_sum += i;
  }
  if (++cal->n < settle + window) return POUR_MOTOR_CAL_RUNNING;
  /* less than a quarter of the test current at the bus's limit: an open phase (R far above any motor's) */
  if (cal->i_sum * 4 < (int64_t)cal->i_test_q15 * window || cal->v_sum <= 0) return POUR_MOTOR_CAL_RESISTANCE;
  /* ΣV < 2^15·4000 (40 kHz at most), so ΣV·v_base·10^6 < 2^64 for bases up to 100 V */
  const uint64_t den = (uint64_t)cal->i_sum * c->i_base_ma;
  const uint64_t r = ((uint64_t)cal->v_sum * c->v_base_mv * 1000000u + den / 2u) / den;
  if (r < POUR_MOTOR_R_MIN_UOHM || r > POUR_MOTOR_R_MAX_UOHM) return POUR_MOTOR_CAL_RESISTANCE;
  /* A star winding reads the same on both axes. One phase open leaves a single path through the other two:
   * 4/3 R along α and 4 R along β (phase c open), no current along one of them (a or b open). */
  if (cal->r_sum_uohm != 0u) {
    const uint64_t ra = cal->r_sum_uohm;
    if ((ra > r ? ra - r : r - ra) * 10u > ra + r) return POUR_MOTOR_CAL_RESISTANCE;
  }
  cal->r_sum_uohm += r;
  cal->n = 0;
  cal->v_sum = cal->i_sum = 0;
  return POUR_MOTOR_CAL_OK;
}

/* ±l_test alternating every period on top of the β vector: each period's current step is l_test·Ts/L with the
 * sign of the half-wave that caused it, whichever period of delay the PWM adds; L = M·l_test·Ts / |Σ s·Δi|. */
static pour_motor_cal_status_t inductance(pour_motor_cal_t *cal, q15_t i, int32_t v_limit, int32_t *v) {
  const pour_motor_cal_config_t *c = &cal->config;
  const int32_t s = (cal->n & 1u) ? -1 : 1;
  if (cal->n >= 2u) cal->l_acc += s * ((int32_t)i - cal->i_prev);
  cal->i_prev = i;
  *v = clamp_i32(cal->v_hold_q15 + s * cal->l_test_q15, -v_limit, v_limit);
  const uint32_t total = periods(cal, POUR_MOTOR_CAL_L_MS);
  if (++cal->n < total) return POUR_MOTOR_CAL_RUNNING;
  if (cal->l_acc == 0) return POUR_MOTOR_CAL_INDUCTANCE;
  /* l_test·v_base·M·(10^9/f) < 2^15·2^16·2^12·2^17 = 2^60; the result in nH */
  const uint64_t num = (uint64_t)cal->l_test_q15 * c->v_base_mv * (total - 2u) * (1000000000u / c->pwm_hz);
  const uint64_t den = (uint64_t)abs_i32(cal->l_acc) * c->i_base_ma;
  const uint64_t l = (num + den / 2u) / den;
  if (l < POUR_MOTOR_L_MIN_NH || l > POUR_MOTOR_L_MAX_NH) return POUR_MOTOR_CAL_INDUCTANCE;
  cal->result.l_phase_nh = (uint32_t)l;
  return POUR_MOTOR_CAL_OK;
}

/* Direction and pole pairs from the forward turn's counts. */
static pour_motor_cal_status_t pole_pairs(pour_motor_cal_t *cal) {
  const int32_t cpr = (int32_t)cal->config.encoder_cpr;
  const int32_t turn = cal->counts - cal->counts_sweep;
  const int32_t a = abs_i32(turn);
  if (a < cpr / (2 * (int32_t)POUR_MOTOR_POLE_PAIRS_MAX)) return POUR_MOTOR_CAL_NO_ENCODER;
  const int32_t pp = (cpr + a / 2) / a;
  if (pp < 1 || pp > (int32_t)POUR_MOTOR_POLE_PAIRS_MAX || abs_i32(pp * a - cpr) > cpr / 8)
    return POUR_MOTOR_CAL_POLE_PAIRS;
  cal->result.pole_pairs = (uint32_t)pp;
  cal->result.encoder_direction = turn > 0 ? 1 : -1;
  return POUR_MOTOR_CAL_OK;
}

/* The offset: mean commanded angle less the mean angle the encoder gives, over both sweeps (rounded). */
static void electrical_offset(pour_motor_cal_t *cal) {
  const pour_motor_cal_config_t *c = &cal->config;
  uint32_t shift = 0;
  while ((c->encoder_cpr << shift) < 65536u) ++shift;
  const int64_t n = cal->sweep_n;
  const int64_t counts = (int64_t)cal->encoder_start * n + cal->counts_sum;
  const int64_t d = cal->angle_sum - cal->result.encoder_direction * (int64_t)cal->result.pole_pairs * counts * (1LL << shift);
  const int64_t mean = d >= 0 ? (d + n / 2) / n : -((-d + n / 2) / n);
  cal->result.electrical_offset = (uint16_t)((uint64_t)mean & 0xFFFFu);
}

static pour_motor_cal_status_t end(pour_motor_cal_status_t st, q15_t *va, q15_t *vb) {
  *va = *vb = 0;
  return st;
}

pour_motor_cal_status_t pour_motor_cal_step(pour_motor_cal_t *cal, q15_t i_alpha, q15_t i_beta, uint16_t encoder,
                                            int32_t v_limit_q15, q15_t *v_alpha, q15_t *v_beta) {
  const pour_motor_cal_config_t *c = &cal->config;
  const int32_t cpr = (int32_t)c->encoder_cpr;
  int32_t step = ((int32_t)encoder - (int32_t)cal->encoder_last) & (cpr - 1);
  if (step >= cpr / 2) step -= cpr;
  cal->encoder_last = encoder;
  cal->counts += step;
  const uint32_t moved = (uint32_t)abs_i32(cal->counts);
  if (moved > cal->result.peak_counts) cal->result.peak_counts = moved;
  if (moved > c->motion_counts) return end(POUR_MOTOR_CAL_MOTION, v_alpha, v_beta);
  const int32_t v_limit = clamp_i32(v_limit_q15, 0, 32767);
  int32_t v = 0;
  pour_motor_cal_status_t st = POUR_MOTOR_CAL_RUNNING;
  switch (cal->stage) {
    case ST_R_ALPHA:
    case ST_R_BETA: {
      const uint8_t beta = cal->stage == ST_R_BETA;
      st = resistance(cal, beta ? i_beta : i_alpha, v_limit, &v);
      *v_alpha = (q15_t)(beta ? 0 : v);
      *v_beta = (q15_t)(beta ? v : 0);
      if (st == POUR_MOTOR_CAL_RUNNING) return st;
      if (st != POUR_MOTOR_CAL_OK) break;
      st = POUR_MOTOR_CAL_RUNNING;
      if (beta) {
        cal->result.r_phase_uohm = (uint32_t)(cal->r_sum_uohm / 2u);
        cal->v_hold_q15 = v;
        cal->stage = ST_L;
      } else {
        cal->stage = ST_R_BETA; /* from the α stage's voltage: the same R wants the same voltage */
      }
      return st;
    }
    case ST_L:
      st = inductance(cal, i_beta, v_limit, &v);
      *v_alpha = 0;
      *v_beta = (q15_t)v;
      if (st == POUR_MOTOR_CAL_RUNNING) return st;
      if (st != POUR_MOTOR_CAL_OK) break;
      cal->stage = ST_FORWARD;
      cal->n = 0;
      cal->counts_sweep = cal->counts;
      return POUR_MOTOR_CAL_RUNNING;
    default: {
      const uint32_t sweep = periods(cal, POUR_MOTOR_CAL_SWEEP_MS);
      int32_t angle = BETA_ANGLE + 65536; /* the dwell's */
      if (cal->stage == ST_FORWARD) angle = BETA_ANGLE + (int32_t)(((uint64_t)cal->n * 65536u) / sweep);
      if (cal->stage == ST_BACK) angle = BETA_ANGLE + 65536 - (int32_t)(((uint64_t)cal->n * 65536u) / sweep);
      if (cal->stage != ST_DWELL) {
        cal->angle_sum += angle;
        cal->counts_sum += cal->counts;
        cal->sweep_n++;
      }
      q15_t s, co;
      pour_foc_sincos_q15((uint16_t)angle, &s, &co);
      const int32_t vh = clamp_i32(cal->v_hold_q15, 0, v_limit);
      *v_alpha = (q15_t)((vh * co + (1 << 14)) >> 15);
      *v_beta = (q15_t)((vh * s + (1 << 14)) >> 15);
      ++cal->n;
      if (cal->stage == ST_FORWARD && cal->n > sweep) {
        cal->stage = ST_DWELL;
        cal->n = 0;
      } else if (cal->stage == ST_DWELL && cal->n >= periods(cal, POUR_MOTOR_CAL_DWELL_MS)) {
        st = pole_pairs(cal);
        if (st != POUR_MOTOR_CAL_OK) break;
        cal->stage = ST_BACK;
        cal->n = 0;
      } else if (cal->stage == ST_BACK && cal->n > sweep) {
        electrical_offset(cal);
        return end(POUR_MOTOR_CAL_OK, v_alpha, v_beta);
      }
      return POUR_MOTOR_CAL_RUNNING;
    }
  }
  return end(st, v_alpha, v_beta);
}
