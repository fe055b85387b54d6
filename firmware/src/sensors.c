/* SPDX-License-Identifier: MIT */
#include "pour/sensors.h"

#include <stddef.h>

#include "pour/params.h"

/* docs/safety.md gives the reasons for each default; encoder_bits's and jump_max_urad's are the declaration's
 * (POUR_PARAMS). */
#define DEFAULT_BANDWIDTH_RAD_S 300u /* θ̇ noise 10 mrad/s rms from 17-bit counts; stable governor loop */
#define DEFAULT_SCALE_MIN_G (-2000)  /* a tared cell reads a little below zero, never 2 kg below */
#define DEFAULT_SCALE_MAX_G 30000    /* the load cells' range: 12.4 kg of liquid (fill +20 %) fits twice */
#define DEFAULT_MASS_MIN_G 1000      /* below 1 kg there is no pour to measure */
#define JUMP_MAX_LIMIT_URAD 1000000  /* · 32² stays below 2^31 */
#define TWO_PI_URAD_Q8 1608495439u   /* round(2π · 10^6 · 2^8): one turn [µrad] Q8 */
#define BANDWIDTH_MAX_RAD_S 1000u    /* ωn T = 1: the loop's double pole at 0 (deadbeat); beyond, unstable */

_Static_assert((-3 >> 1) == -2, "arithmetic right shift required"); /* rounding shifts, as Python's >> */

/* The declaration's rows of group sensors (POUR_PARAMS, pour/params.h); the other groups' live elsewhere. */
#define SENSORS_ROW_safety(member, type, value)
#define SENSORS_ROW_stop(member, type, value)
#define SENSORS_ROW_sensors(member, type, value) c.member = (type)(value);
#define SENSORS_ROW_supervisor(member, type, value)
#define SENSORS_ROW_port(member, type, value)
#define SENSORS_DEFAULT(id, name, unit, def, lo, hi, type, group, member, doc) SENSORS_ROW_##group(member, type, def)

pour_sensors_config_t pour_sensors_default_config(void) {
  pour_sensors_config_t c;
  POUR_PARAMS(SENSORS_DEFAULT)
  c.bandwidth_rad_s = DEFAULT_BANDWIDTH_RAD_S;
  c.scale_min_g = DEFAULT_SCALE_MIN_G;
  c.scale_max_g = DEFAULT_SCALE_MAX_G;
  c.mass_min_g = DEFAULT_MASS_MIN_G;
  return c;
}

pour_status_t pour_estimator_init(pour_estimator_t *est, const pour_sensors_config_t *config) {
  if (est == NULL || config == NULL) {
    return POUR_EINVAL;
  }
  const pour_sensors_config_t *c = config;
  if (c->encoder_bits < POUR_ENCODER_BITS_MIN || c->encoder_bits > POUR_ENCODER_BITS_MAX ||
      c->bandwidth_rad_s < 1u || c->bandwidth_rad_s > BANDWIDTH_MAX_RAD_S || c->scale_min_g < -POUR_SCALE_LIMIT_G ||
      c->scale_max_g > POUR_SCALE_LIMIT_G || c->scale_max_g <= c->scale_min_g || c->mass_min_g < 1 ||
      c->jump_max_urad < 1 || c->jump_max_urad > JUMP_MAX_LIMIT_URAD) {
    return POUR_EINVAL;
  }
  est->config = *c;
  /* Forward-Euler observer at T = 1 ms: e = θ - θ̂; θ̂ += T ω̂ + k1 T e; ω̂ += k2 T e. Its error poles
   * solve z² - (2 - k1 T) z + (1 - k1 T + k2 T²) = 0: k1 = 2 ωn, k2 = ωn² give the double root
   * z = 1 - ωn T, critically damped in discrete time too. */
  const int64_t bw = c->bandwidth_rad_s;
  est->gain_theta_q24 = (int32_t)((2 * bw * (1 << 24) + 500) / 1000);
  est->gain_omega_q24 = (int32_t)((bw * bw * (1 << 24) + 500000) / 1000000);
  est->empty_ok = false;
  pour_estimator_reset(est);
  return POUR_OK;
}

void pour_estimator_expect_empty(pour_estimator_t *est, bool empty) { est->empty_ok = empty; }

void pour_estimator_reset(pour_estimator_t *est) {
  est->started = false;
  est->last_seq = 0u;
  est->theta_q16 = 0;
  est->omega_q16 = 0;
  est->m0_g = 0;
}

int32_t pour_sensors_theta_urad(uint32_t count, uint8_t bits) {
  const uint32_t half = 1u << (bits - 1u);
  const bool below = count > half; /* wrapped: the bucket is tilted back past upright */
  const uint32_t mag = below ? (1u << bits) - count : count; /* <= 2^(bits-1) <= 2^23 */
  /* mag · 2π·10^6·2^8 < 2^23 · 2^31: one 32x32 -> 64 multiply; rounded half up on the magnitude, so that
   * θ(-c) = -θ(c). The table constant's rounding errs by < 0.001 µrad at π. */
  const uint64_t scaled = (uint64_t)mag * TWO_PI_URAD_Q8 + ((uint64_t)1 << (bits + 7u));
  const int32_t theta = (int32_t)(scaled >> (bits + 8u));
  return below ? -theta : theta;
}

/* round(32768 num / den) clipped to [0, 32767], for 0 < den < 2^16: num < den keeps 32768 num + den/2
 * below 2^31, one 32-bit divide. Round half up, as Python's (num * 32768 + den // 2) // den. */
static q15_t mass_ratio_q15(int32_t num, int32_t den) {
  if (num <= 0) {
    return 0;
  }
  if (num >= den) {
    return POUR_Q15_MAX;
  }
  const uint32_t q = ((uint32_t)num * 32768u + (uint32_t)den / 2u) / (uint32_t)den;
  return (q15_t)(q > (uint32_t)POUR_Q15_MAX ? (uint32_t)POUR_Q15_MAX : q);
}

static bool scale_ok(const pour_sensors_config_t *c, int32_t g) { return g >= c->scale_min_g && g <= c->scale_max_g; }

bool pour_estimator_update(pour_estimator_t *est, const pour_sensors_t *sample, pour_state_t *state) {
  const pour_sensors_config_t *c = &est->config;
  if (sample->encoder >= (1u << c->encoder_bits) || !scale_ok(c, sample->scale_rotating_g) ||
      !scale_ok(c, sample->scale_target_g)) {
    return false;
  }
  const int32_t m0 = est->started ? est->m0_g : sample->scale_rotating_g + sample->scale_target_g;
  const bool empty = m0 < c->mass_min_g;
  if (empty && !est->empty_ok) {
    return false;
  }
  const int32_t theta = pour_sensors_theta_urad(sample->encoder, c->encoder_bits);
  int64_t advance_q16 = 0; /* θ̂'s advance over this tick [µrad/tick] Q16: 0 on the first sample (at rest) */
  if (!est->started) {
    est->started = true;
    est->m0_g = m0;
    est->theta_q16 = (int64_t)theta * 65536;
    est->omega_q16 = 0;
  } else {
    /* Missed samples: the loop coasts on its speed over the gap, then corrects once. */
    uint32_t gap = sample->seq - est->last_seq;
    gap = gap < 1u ? 1u : (gap > POUR_ESTIMATOR_GAP_MAX ? POUR_ESTIMATOR_GAP_MAX : gap);
    int64_t predicted_q16 = est->theta_q16;
    if (gap > 1u) {
      predicted_q16 += (int64_t)(gap - 1u) * est->omega_q16;
    }
    /* |θ| <= π·10^6 and θ̂ stays within a bounded error of it (a stable loop), so e fits int32; e · gain
     * < 2^31 · 2^25: int64. */
    const int32_t e = pour_sat_i32((int64_t)theta - ((predicted_q16 + 32768) >> 16));
    /* The loop's own error under an acceleration a is a/ωn² (3.9 mrad at 350 rad/s², full torque on the
     * empty bucket, and ωn = 300 rad/s): a reading beyond jump_max · n² off the prediction is a count that
     * jumped (a sign flipped, a bit lost), not a motion. Refused before it moves the loop. */
    const int32_t allowed = c->jump_max_urad * (int32_t)(gap * gap);
    if (e > allowed || e < -allowed) {
      return false;
    }
    est->theta_q16 = predicted_q16;
    advance_q16 = est->omega_q16 + (((int64_t)e * est->gain_theta_q24 + 128) >> 8);
    est->theta_q16 += advance_q16;
    est->omega_q16 += ((int64_t)e * est->gain_omega_q24 + 128) >> 8;
  }
  est->last_seq = sample->seq;
  state->seq = sample->seq;
  state->theta_urad = theta;
  /* θ̇ is the loop's advance over this tick, ω̂ + k1 T e, not ω̂ alone: under a constant acceleration a, ω̂
   * lags by k1 a / k2 = 2 a / ωn (a 6.7 ms delay at 300 rad/s, 1.3 rad/s behind at 200 rad/s²), the advance
   * does not. Its price, the quantisation noise through k1, is measured in docs/safety.md.
   * µrad/tick Q16 -> µrad/s: · 1000, rounded. */
  state->omega_urad_s = pour_sat_i32((advance_q16 * 1000 + 32768) >> 16);
  state->v_rotating = empty ? 0 : mass_ratio_q15(sample->scale_rotating_g, m0);
  state->v_target = empty ? 0 : mass_ratio_q15(sample->scale_target_g, m0);
  /* What neither cell carries: spilled, or in flight between the buckets (none of an empty bucket). */
  const int32_t spill = empty ? 0 : POUR_Q15_ONE_INT - state->v_rotating - state->v_target;
  state->v_spill = (q15_t)(spill < 0 ? 0 : (spill > POUR_Q15_MAX ? POUR_Q15_MAX : spill));
  return true;
}
