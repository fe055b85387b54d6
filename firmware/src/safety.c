/* SPDX-License-Identifier: MIT */
#include "pour/safety.h"

#include <stdbool.h>
#include <stddef.h>

#include "pour/params.h"

#define KNEE_SPAN_MAX_URAD 8388608        /* knee - θ saturates at 2^23 µrad (8.4 rad) in the braking curve */

/* The defaults are the declaration's rows of group safety (POUR_PARAMS, pour/params.h, which gives the reasons
 * with docs/safety.md); the other groups' rows live elsewhere. */
#define SAFETY_ROW_safety(member, type, value) config.member = (type)(value);
#define SAFETY_ROW_stop(member, type, value)
#define SAFETY_ROW_sensors(member, type, value)
#define SAFETY_ROW_supervisor(member, type, value)
#define SAFETY_ROW_port(member, type, value)
#define SAFETY_DEFAULT(id, name, unit, def, lo, hi, type, group, member, doc) SAFETY_ROW_##group(member, type, def)

pour_safety_config_t pour_safety_default_config(void) {
  pour_safety_config_t config;
  POUR_PARAMS(SAFETY_DEFAULT)
  return config;
}

pour_status_t pour_safety_init(pour_safety_t *safety, const pour_safety_config_t *config) {
  if (safety == NULL || config == NULL) {
    return POUR_EINVAL;
  }
  const pour_safety_config_t *c = config;
  if (c->tau_limit <= 0 || c->slew_per_tick <= 0 || c->theta_max_urad <= c->theta_min_urad ||
      c->omega_max_urad_s <= 0 || c->omega_max_urad_s > POUR_SAFETY_OMEGA_MAX_URAD_S || c->alpha_max_urad_s2 < 1000 ||
      c->omega_slack_urad_s <= 0 || c->omega_slack_urad_s > POUR_SAFETY_OMEGA_MAX_URAD_S || c->governor_gain <= 0 ||
      c->knee_theta_urad < 0 || c->knee_theta_urad > POUR_SAFETY_KNEE_MAX_URAD || c->slow_omega_urad_s <= 0 ||
      c->slow_omega_urad_s > POUR_SAFETY_OMEGA_MAX_URAD_S || c->knee_decel_urad_s2 < 1000 ||
      c->knee_decel_urad_s2 > POUR_SAFETY_DECEL_MAX_URAD_S2 || c->slow_torque_ff < 0) {
    return POUR_EINVAL;
  }
  safety->config = *c;
  safety->torque = 0;
  safety->active = 0u;
  safety->alpha_step_urad_s = (int32_t)(((int64_t)c->alpha_max_urad_s2 + 500) / 1000);
  safety->gain_q32 = (int32_t)(((int64_t)c->governor_gain * ((int64_t)1 << 32) + 500000) / 1000000);
  safety->ceiling_urad_s = c->omega_slack_urad_s;
  safety->floor_urad_s = -c->omega_slack_urad_s;
  safety->integral_mq15 = 0;
  return POUR_OK;
}

void pour_safety_restart(pour_safety_t *safety) {
  safety->torque = 0;
  safety->active = 0u;
  safety->ceiling_urad_s = safety->config.omega_slack_urad_s;
  safety->floor_urad_s = -safety->config.omega_slack_urad_s;
  safety->integral_mq15 = 0;
}

/* Zero for a torque that would drive further past an angle limit, else the torque itself. */
static q15_t angle_cut(const pour_safety_config_t *c, q15_t torque, int32_t theta_urad, uint8_t *active) {
  if (torque > 0 && theta_urad >= c->theta_max_urad) {
    *active |= POUR_LIMIT_ANGLE_MAX;
    return 0;
  }
  if (torque < 0 && theta_urad <= c->theta_min_urad) {
    *active |= POUR_LIMIT_ANGLE_MIN;
    return 0;
  }
  return torque;
}

static int32_t min3(int32_t a, int32_t b, int32_t c) { return a < b ? (a < c ? a : c) : (b < c ? b : c); }
static int32_t max3(int32_t a, int32_t b, int32_t c) { return a > b ? (a > c ? a : c) : (b > c ? b : c); }

/* Torque bound for a speed margin [µrad/s]: K · margin, Q15, rounded half up, within ±tau_limit.
 * |margin| <= 2 · 10^8 < 2^28 and gain < 2^28: the product fits int64 (one 32x32 -> 64 multiply); the
 * result before the clamp < 2^24, so the int32 cast is exact. */
static int32_t band_torque(const pour_safety_t *s, int32_t margin_urad_s) {
  const int32_t t = (int32_t)(((int64_t)margin_urad_s * s->gain_q32 + ((int64_t)1 << 31)) >> 32);
  const int32_t lim = s->config.tau_limit;
  return t > lim ? lim : (t < -lim ? -lim : t);
}

/* floor(sqrt(x)) for x < 2^62, bit by bit on the root from its top bit down: one 32x32 -> 64 multiply and a
 * compare a bit, ceil(len(x) / 2) bits (21 for a speed limit near 2 rad/s), no division. */
static uint32_t isqrt64(uint64_t x) {
  if (x == 0u) {
    return 0u;
  }
#if defined(__GNUC__)
  const unsigned len = 64u - (unsigned)__builtin_clzll(x);
#else
  unsigned len = 0u;
  for (uint64_t y = x; y != 0u; y >>= 1) {
    ++len;
  }
#endif
  uint32_t root = 0u;
  for (uint32_t bit = 1u << ((len - 1u) / 2u); bit != 0u; bit >>= 1) {
    const uint32_t t = root | bit;
    if ((uint64_t)t * t <= x) {
      root = t;
    }
  }
  return root;
}

/* The speed limit at the tilt θ: omega_max, and with a knee the fill schedule's: slow past it, before it
 * sqrt(slow² + 2 · decel · (knee - θ)) up to omega_max (the root only where it is below: sq < omega_max²).
 * slow < 2^27, decel <= 10^9, knee - θ <= 2^23: the sum < 2^55. */
static int32_t speed_limit(const pour_safety_config_t *c, int32_t theta_urad) {
  if (c->knee_theta_urad == 0) {
    return c->omega_max_urad_s;
  }
  const int32_t slow = c->slow_omega_urad_s < c->omega_max_urad_s ? c->slow_omega_urad_s : c->omega_max_urad_s;
  if (theta_urad >= c->knee_theta_urad) {
    return slow;
  }
  const int64_t span = (int64_t)c->knee_theta_urad - theta_urad;
  const uint64_t d = (uint64_t)(span > KNEE_SPAN_MAX_URAD ? KNEE_SPAN_MAX_URAD : span);
  const uint64_t sq = (uint64_t)slow * (uint64_t)slow + 2u * (uint64_t)c->knee_decel_urad_s2 * d;
  const uint64_t top = (uint64_t)c->omega_max_urad_s * (uint64_t)c->omega_max_urad_s;
  return sq < top ? (int32_t)isqrt64(sq) : c->omega_max_urad_s;
}

/* Moves the band one tick on from the speed θ̇ [µrad/s] under the limit lim; returns the torque bounds it
 * implies, Q15, and the speed θ̇ saturated as the bounds used it. */
static int32_t band_bounds(pour_safety_t *s, int32_t lim, int32_t omega_urad_s, int32_t *lo, int32_t *hi) {
  const pour_safety_config_t *c = &s->config;
  /* Speeds saturate at ±100 rad/s (twice the plausible), which keeps every sum below in int32. */
  const int32_t w = omega_urad_s > POUR_SAFETY_OMEGA_MAX_URAD_S
                        ? POUR_SAFETY_OMEGA_MAX_URAD_S
                        : (omega_urad_s < -POUR_SAFETY_OMEGA_MAX_URAD_S ? -POUR_SAFETY_OMEGA_MAX_URAD_S : omega_urad_s);
  s->ceiling_urad_s = min3(lim, s->ceiling_urad_s + s->alpha_step_urad_s, (w > 0 ? w : 0) + c->omega_slack_urad_s);
  s->floor_urad_s = max3(-c->omega_max_urad_s, s->floor_urad_s - s->alpha_step_urad_s,
                         (w < 0 ? w : 0) - c->omega_slack_urad_s);
  *hi = band_torque(s, s->ceiling_urad_s - w);
  *lo = band_torque(s, s->floor_urad_s - w);
  return w;
}

/* The limit bit for a cut at the ceiling (or floor): the speed limit itself, or the band still ramping. */
static uint8_t band_bit(int32_t edge_urad_s, int32_t limit_urad_s) {
  return edge_urad_s == limit_urad_s ? POUR_LIMIT_SPEED : POUR_LIMIT_ACCEL;
}

q15_t pour_safety_apply(pour_safety_t *safety, q15_t requested, int32_t theta_urad, int32_t omega_urad_s) {
  const pour_safety_config_t *c = &safety->config;
  uint8_t active = 0u;
  int32_t cmd = angle_cut(c, requested, theta_urad, &active);
  if (cmd > c->tau_limit) {
    cmd = c->tau_limit;
    active |= POUR_LIMIT_CLAMP;
  } else if (cmd < -(int32_t)c->tau_limit) {
    cmd = -(int32_t)c->tau_limit;
    active |= POUR_LIMIT_CLAMP;
  }
  /* The speed band: the band follows the speed from within slack and widens by at most one alpha step a
   * tick, so |θ̇| can grow only as fast as the band does; the torque is kept within K (edge - θ̇), which
   * turns into a brake beyond an edge. Braking, toward either edge, is never limited. */
  int32_t lo;
  int32_t hi;
  const int32_t lim = speed_limit(c, theta_urad);
  const int32_t w = band_bounds(safety, lim, omega_urad_s, &lo, &hi);
  const uint8_t hi_bit = band_bit(safety->ceiling_urad_s, lim);
  const uint8_t lo_bit = band_bit(safety->floor_urad_s, -c->omega_max_urad_s);
  if (lim < c->omega_max_urad_s) {
    /* Where the schedule slows the bucket (the braking curve's last stretch, and past the knee), a slow
     * ceiling must still lift the load: the feed-forward and the integral carry what K (ceiling - θ̇) alone
     * cannot (it would stall the bucket short of the knee), and the bound never speeds the bucket beyond
     * omega_max. */
    const int32_t proportional = hi; /* K (ceiling - θ̇) */
    const int32_t lim_hi = band_torque(safety, c->omega_max_urad_s - w); /* within ±tau_limit */
    const int32_t sum = proportional + c->slow_torque_ff + safety->integral_mq15 / 1000; /* each term < 2^16 */
    hi = sum < lim_hi ? sum : lim_hi;
    if (cmd > hi || safety->ceiling_urad_s < w) { /* integrate only while the bound governs: no windup */
      const int64_t next = (int64_t)safety->integral_mq15 + (int64_t)proportional * c->slow_ki_per_s;
      const int64_t top = (int64_t)c->tau_limit * 500;
      safety->integral_mq15 = (int32_t)(next < 0 ? 0 : (next > top ? top : next));
    }
  } else {
    safety->integral_mq15 = 0;
  }
  if (cmd > hi) {
    cmd = hi;
    active |= hi_bit;
  } else if (cmd < lo) {
    cmd = lo;
    active |= lo_bit;
  }
  const int32_t delta = cmd - (int32_t)safety->torque; /* |delta| < 2^16: no overflow */
  if (delta > c->slew_per_tick) {
    cmd = safety->torque + c->slew_per_tick;
    active |= POUR_LIMIT_SLEW;
  } else if (delta < -(int32_t)c->slew_per_tick) {
    cmd = safety->torque - c->slew_per_tick;
    active |= POUR_LIMIT_SLEW;
  }
  /* A slewed command can still push beyond the band, or carry the old sign past an angle limit: cut it
   * now, toward zero, since less torque never has to wait for the slew (a brake that needs the other sign
   * builds up through the slew from zero). */
  const int32_t hi_cut = hi > 0 ? hi : 0;
  const int32_t lo_cut = lo < 0 ? lo : 0;
  if (cmd > hi_cut) {
    cmd = hi_cut;
    active |= hi_bit;
  } else if (cmd < lo_cut) {
    cmd = lo_cut;
    active |= lo_bit;
  }
  cmd = angle_cut(c, (q15_t)cmd, theta_urad, &active);
  safety->torque = (q15_t)cmd;
  safety->active = active;
  return safety->torque;
}

void pour_safety_force(pour_safety_t *safety, q15_t torque) {
  safety->torque = torque;
  safety->active = 0u;
}

q15_t pour_safety_hold(pour_safety_t *safety, q15_t target) {
  const int32_t now = safety->torque;
  const bool toward_zero = (now >= 0 && target >= 0 && target <= now) || (now <= 0 && target <= 0 && target >= now);
  const int32_t slew = safety->config.slew_per_tick;
  int32_t cmd = target;
  safety->active = 0u;
  if (!toward_zero && (cmd > now + slew || cmd < now - slew)) {
    cmd = cmd > now ? now + slew : now - slew;
    safety->active = POUR_LIMIT_SLEW;
  }
  safety->torque = (q15_t)cmd;
  return safety->torque;
}
