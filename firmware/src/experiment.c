/* SPDX-License-Identifier: MIT */
#include "pour/experiment.h"

#include <stddef.h>

/* The identify script [ms]: a ramp to the hold angle, steps (alternating every STEP_HALF_MS), a chirp
 * from f0 to f1, a sweep, a ramp back. 18 s in all: the empty bucket needs no more to show its inertia,
 * friction, gravity arm, latency and the scale's filter. The sweep runs a triangle of ±SWEEP_URAD about
 * the hold angle, one cycle at 0.5 rad/s, then three at 1.5 rad/s (within the envelope's 2 rad/s): two
 * steady speeds each way are what tell viscous friction (b θ̇, a few % of Coulomb's) from Coulomb's. */
#define RAMP_MS 1500u
#define STEPS_MS 3000u
#define STEP_HALF_MS 250u
#define CHIRP_MS 8000u
#define SWEEP_URAD 250000u
#define SWEEP_SLOW_MS 2000u      /* one cycle: 4 * SWEEP_URAD at SWEEP_SLOW_URAD_MS */
#define SWEEP_SLOW_URAD_MS 500u  /* [µrad/ms] = [mrad/s] */
#define SWEEP_FAST_MS 2000u      /* three cycles */
#define SWEEP_FAST_URAD_MS 1500u
#define SWEEP_MS (SWEEP_SLOW_MS + SWEEP_FAST_MS)
#define TILT_DWELL_MS 1000u
#define TILT_RETURN_FACTOR 4 /* the empty bucket comes back four times as fast as it went */
#define ANGLE_MAX_URAD 3141593   /* angles and ranges within half a turn */
#define SPEED_MAX_URAD_S 2000000 /* the tilt within the envelope's 2 rad/s */

pour_experiment_config_t pour_experiment_default_config(void) {
  pour_experiment_config_t c;
  c.hold_theta_urad = 350000;  /* 20 deg: gravity's arm is felt, far from the lip */
  c.range_urad = 400000;       /* 20 +- 23 deg: [-3, 43] deg */
  c.kp_per_rad = 16384;        /* 0.5 tau_max / rad: friction and gravity leave < 0.1 rad of error */
  c.kd_per_rad_s = 1638;       /* 0.05 tau_max per rad/s: damping ratio ~0.8 on the empty bucket */
  c.step_torque = 2458;        /* 0.075 tau_max: ~0.15 rad against the hold stiffness */
  c.chirp_torque = 1966;       /* 0.06 tau_max */
  c.prbs_torque = 1638;        /* 0.05 tau_max: each flip one slew step, an edge every ~16 ms whose timing
                                * shows the command's latency to the tick */
  c.prbs_bit_ms = 8u;
  c.chirp_f0_mhz = 500u;       /* 0.5 Hz .. */
  c.chirp_f1_mhz = 6000u;      /* .. 6 Hz: past the hold's resonance, into the inertia's range */
  c.tilt_theta_urad = 1570796; /* 90 deg: all of the liquid is out */
  c.tilt_speed_urad_s = 100000; /* 0.1 rad/s: a slow pour, the weir's quasi-steady flow */
  c.tilt_margin_urad = 87266;  /* 5 deg */
  c.tilt_kp_per_rad = 65536;   /* 2 tau_max / rad: the full bucket's gravity torque leaves < 0.1 rad */
  c.tilt_kd_per_rad_s = 6554;  /* 0.2 tau_max per rad/s */
  return c;
}

pour_status_t pour_experiment_validate(const pour_experiment_config_t *c) {
  if (c == NULL || c->hold_theta_urad <= 0 || c->hold_theta_urad > ANGLE_MAX_URAD || c->range_urad < c->hold_theta_urad ||
      c->range_urad > ANGLE_MAX_URAD || c->tilt_theta_urad > ANGLE_MAX_URAD || c->tilt_margin_urad > ANGLE_MAX_URAD ||
      c->tilt_speed_urad_s > SPEED_MAX_URAD_S || c->kp_per_rad <= 0 ||
      c->kd_per_rad_s < 0 || c->step_torque <= 0 || c->chirp_torque <= 0 || c->prbs_torque < 0 || c->prbs_bit_ms < 1u || c->chirp_f0_mhz == 0u ||
      c->chirp_f1_mhz <= c->chirp_f0_mhz || c->chirp_f1_mhz > 50000u || c->tilt_theta_urad <= 0 ||
      c->tilt_speed_urad_s <= 0 || c->tilt_margin_urad <= 0 || c->tilt_kp_per_rad <= 0 || c->tilt_kd_per_rad_s < 0) {
    return POUR_EINVAL;
  }
  return POUR_OK;
}

/* Ticks of the tilt up [ms], rounded up. */
static uint32_t tilt_up_ms(const pour_experiment_config_t *c) {
  return (uint32_t)(((int64_t)c->tilt_theta_urad * 1000 + c->tilt_speed_urad_s - 1) / c->tilt_speed_urad_s);
}

uint32_t pour_experiment_duration_ms(const pour_experiment_config_t *c, uint8_t kind) {
  if (kind == (uint8_t)POUR_EXPERIMENT_IDENTIFY) {
    return RAMP_MS + STEPS_MS + CHIRP_MS + SWEEP_MS + RAMP_MS;
  }
  if (kind == (uint8_t)POUR_EXPERIMENT_TILT) {
    const uint32_t up = tilt_up_ms(c);
    return up + TILT_DWELL_MS + up / TILT_RETURN_FACTOR + 1u;
  }
  return 0u;
}

void pour_experiment_start(pour_experiment_t *e, const pour_experiment_config_t *config, uint8_t kind) {
  e->config = *config;
  e->kind = kind;
  e->phase = kind == (uint8_t)POUR_EXPERIMENT_TILT ? (uint8_t)POUR_EXPERIMENT_PHASE_TILT
                                                   : (uint8_t)POUR_EXPERIMENT_PHASE_RAMP;
  e->started = false;
  e->ms = 0u;
  e->start_theta_urad = 0;
  e->phase_turn = 0u;
  e->lfsr = 0xACE1u;
}

/* a + (b - a) * num / den [µrad], den > 0, 0 <= num <= den. */
static int32_t lerp(int32_t a, int32_t b, uint32_t num, uint32_t den) {
  return (int32_t)(a + ((int64_t)b - a) * (int64_t)num / (int64_t)den);
}

/* A PD torque toward ref: gains [Q15 / rad], [Q15 / (rad/s)]; angles [µrad], speed [µrad/s]. The result
 * is kept in int32 (|err| < 2^32 µrad, gains < 2^31: the int64 product is exact). */
static int32_t pd(int32_t kp, int32_t kd, int32_t ref_urad, const pour_state_t *s) {
  const int64_t t = ((int64_t)ref_urad - s->theta_urad) * kp / 1000000 - (int64_t)s->omega_urad_s * kd / 1000000;
  return pour_sat_i32(t);
}

/* pd toward ref moving at speed [µrad/s]: the damping acts on the speed error, so that a ramp is tracked
 * without a lag of kd * speed / kp. */
static int32_t track(int32_t kp, int32_t kd, int32_t ref_urad, int32_t speed_urad_s, const pour_state_t *s) {
  pour_state_t rel = *s;
  rel.omega_urad_s = pour_sat_i32((int64_t)s->omega_urad_s - speed_urad_s);
  return pd(kp, kd, ref_urad, &rel);
}

/* sin(2π · turn / 2^32) by the parabola 4x(1 - |x|), x = the phase in half turns in [-1, 1), Q15; within
 * 0.06 of the sine, smooth, and the fitter sees the command itself, so its shape need not be exact. */
static int32_t sine_q15(uint32_t turn) {
  const int32_t x = (int32_t)(turn >> 16) - (turn >= 0x80000000u ? 65536 : 0); /* Q15 of a half turn */
  const int32_t ax = x < 0 ? -x : x;
  const int64_t s = ((int64_t)4 * x * (POUR_Q15_ONE_INT - ax)) >> 15;
  return s > POUR_Q15_MAX ? POUR_Q15_MAX : (int32_t)s;
}

/* The chirp's frequency now [mHz]: linear in time from f0 to f1 over CHIRP_MS. */
static uint32_t chirp_mhz(const pour_experiment_config_t *c, uint32_t t_ms) {
  return c->chirp_f0_mhz + (uint32_t)(((uint64_t)(c->chirp_f1_mhz - c->chirp_f0_mhz) * t_ms) / CHIRP_MS);
}

static int32_t identify(pour_experiment_t *e, const pour_state_t *s) {
  const pour_experiment_config_t *c = &e->config;
  const uint32_t t = e->ms;
  const int32_t hold = c->hold_theta_urad;
  int32_t ref = hold;
  int32_t speed = 0;
  int32_t excite = 0;
  if (t < RAMP_MS) {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_RAMP;
    ref = lerp(e->start_theta_urad, hold, t, RAMP_MS);
  } else if (t < RAMP_MS + STEPS_MS) {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_STEPS;
    excite = (((t - RAMP_MS) / STEP_HALF_MS) & 1u) == 0u ? c->step_torque : -c->step_torque;
    if ((t - RAMP_MS) % c->prbs_bit_ms == 0u) {
      const uint32_t r = e->lfsr;
      const uint32_t bit = (r ^ (r >> 2) ^ (r >> 3) ^ (r >> 5)) & 1u;
      e->lfsr = (uint16_t)((r >> 1) | (bit << 15));
    }
    excite += (e->lfsr & 1u) != 0u ? c->prbs_torque : -c->prbs_torque;
  } else if (t < RAMP_MS + STEPS_MS + CHIRP_MS) {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_CHIRP;
    /* One tick advances the phase by f [mHz] * 2^32 / 10^6 (f <= 50 Hz: < 2^28 a tick). */
    e->phase_turn += (uint32_t)(((uint64_t)chirp_mhz(c, t - RAMP_MS - STEPS_MS) << 32) / 1000000u);
    excite = (c->chirp_torque * sine_q15(e->phase_turn)) / POUR_Q15_ONE_INT;
  } else if (t < RAMP_MS + STEPS_MS + CHIRP_MS + SWEEP_MS) {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_SWEEP;
    /* Along the triangle [µrad]: up to +SWEEP_URAD, down to -SWEEP_URAD, up to the hold angle. */
    const uint32_t k = t - (RAMP_MS + STEPS_MS + CHIRP_MS);
    const bool fast = k >= SWEEP_SLOW_MS;
    const uint32_t v = fast ? SWEEP_FAST_URAD_MS : SWEEP_SLOW_URAD_MS;
    const int32_t p = (int32_t)(((fast ? k - SWEEP_SLOW_MS : k) * v) % (4u * SWEEP_URAD));
    const int32_t a = (int32_t)SWEEP_URAD;
    speed = (p < a || p >= 3 * a ? 1000 : -1000) * (int32_t)v;
    ref = hold + (p < a ? p : (p < 3 * a ? 2 * a - p : p - 4 * a));
  } else {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_BACK;
    ref = lerp(hold, e->start_theta_urad, t - (RAMP_MS + STEPS_MS + CHIRP_MS + SWEEP_MS), RAMP_MS);
  }
  return track(c->kp_per_rad, c->kd_per_rad_s, ref, speed, s) + excite;
}

static int32_t tilt(pour_experiment_t *e, const pour_state_t *s) {
  const pour_experiment_config_t *c = &e->config;
  const uint32_t up = tilt_up_ms(c);
  const uint32_t t = e->ms;
  int32_t ref;
  int32_t speed;
  if (t < up) {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_TILT;
    ref = lerp(e->start_theta_urad, c->tilt_theta_urad, t, up);
    speed = c->tilt_speed_urad_s;
  } else if (t < up + TILT_DWELL_MS) {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_DWELL;
    ref = c->tilt_theta_urad;
    speed = 0;
  } else {
    e->phase = (uint8_t)POUR_EXPERIMENT_PHASE_RETURN;
    const uint32_t back = up / TILT_RETURN_FACTOR + 1u;
    const uint32_t k = t - up - TILT_DWELL_MS;
    ref = lerp(c->tilt_theta_urad, e->start_theta_urad, k < back ? k : back, back);
    speed = -c->tilt_speed_urad_s * TILT_RETURN_FACTOR;
  }
  return track(c->tilt_kp_per_rad, c->tilt_kd_per_rad_s, ref, speed, s);
}

static bool in_range(const pour_experiment_t *e, int32_t theta) {
  const pour_experiment_config_t *c = &e->config;
  if (e->kind == (uint8_t)POUR_EXPERIMENT_TILT) {
    return theta >= -c->tilt_margin_urad && (int64_t)theta <= (int64_t)c->tilt_theta_urad + c->tilt_margin_urad;
  }
  const int64_t off = (int64_t)theta - c->hold_theta_urad;
  return off <= c->range_urad && off >= -(int64_t)c->range_urad;
}

q15_t pour_experiment_step(pour_experiment_t *e, const pour_state_t *state, bool *ended) {
  *ended = false;
  if (e->kind == (uint8_t)POUR_EXPERIMENT_NONE) {
    return 0;
  }
  if (!e->started) {
    e->started = true;
    e->start_theta_urad = state->theta_urad;
  }
  const bool over = e->ms >= pour_experiment_duration_ms(&e->config, e->kind);
  if (over || !in_range(e, state->theta_urad)) {
    e->phase = over ? (uint8_t)POUR_EXPERIMENT_PHASE_DONE : (uint8_t)POUR_EXPERIMENT_PHASE_OUT_OF_RANGE;
    e->kind = (uint8_t)POUR_EXPERIMENT_NONE;
    *ended = true;
    return 0;
  }
  const int32_t request = e->kind == (uint8_t)POUR_EXPERIMENT_TILT ? tilt(e, state) : identify(e, state);
  e->ms++;
  return pour_sat_q15(request);
}
