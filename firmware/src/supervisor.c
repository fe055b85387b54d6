/* SPDX-License-Identifier: MIT */
#include "pour/supervisor.h"

#include <stddef.h>

#include "pour/control.h"

/* docs/safety.md gives the reason for each default; the figures come from 20 held-out pours of the shipped
 * policy and 5 of the hand-written baseline in the simulator (tau_max 20 N·m, 10 kg of liquid). */
#define DEFAULT_THETA_MARGIN_URAD 87266     /* 5 deg past the envelope's limits */
#define DEFAULT_OMEGA_MAX_URAD_S 22000000   /* 22 rad/s: nominal peak 16.0 rad/s + 35 % */
#define DEFAULT_WINDOW_MS 10u
#define DEFAULT_TORQUE_MIN 16384            /* 0.5 tau_max = 10 N·m, twice the liquid's worst gravity torque */
#define DEFAULT_OMEGA_AGAINST_URAD_S 300000 /* 0.3 rad/s */
#define DEFAULT_AGAINST_MS 3u
#define DEFAULT_ENCODER_MOVE_URAD 500       /* 10 ms at >= 0.5 tau_max move the full bucket >= 1,800 urad */
#define DEFAULT_VOLUME_STEP_MAX 2621        /* 8 % of the liquid per tick; nominal worst 2.7 % */
#define DEFAULT_ACCEL_FULL_URAD_S2 350000000    /* 350 rad/s²: 20 N·m on the empty bucket measured 335 */
#define DEFAULT_ACCEL_PASSIVE_URAD_S2 150000000 /* 150 rad/s²: nominal never beyond it 2 ticks in a row */
#define SEQ_ADVANCE_MAX 32767u              /* a forward gap larger than this is a jump back, not a gap */
#define VOLUME_GAP_MAX 32u                  /* missed ticks credited to a volume change, at most */

pour_supervisor_config_t pour_supervisor_default_config(void) {
  pour_supervisor_config_t c;
  c.checks = POUR_CHECK_ALL;
  c.theta_margin_urad = DEFAULT_THETA_MARGIN_URAD;
  c.omega_max_urad_s = DEFAULT_OMEGA_MAX_URAD_S;
  c.window_ms = DEFAULT_WINDOW_MS;
  c.torque_min = DEFAULT_TORQUE_MIN;
  c.omega_against_urad_s = DEFAULT_OMEGA_AGAINST_URAD_S;
  c.against_ms = DEFAULT_AGAINST_MS;
  c.encoder_move_urad = DEFAULT_ENCODER_MOVE_URAD;
  c.volume_step_max = DEFAULT_VOLUME_STEP_MAX;
  c.accel_full_urad_s2 = DEFAULT_ACCEL_FULL_URAD_S2;
  c.accel_passive_urad_s2 = DEFAULT_ACCEL_PASSIVE_URAD_S2;
  return c;
}

pour_status_t pour_supervisor_init(pour_supervisor_t *sup, const pour_supervisor_config_t *config,
                                   int32_t theta_min_urad, int32_t theta_max_urad) {
  if (sup == NULL || config == NULL) {
    return POUR_EINVAL;
  }
  const pour_supervisor_config_t *c = config;
  if ((c->checks & ~POUR_CHECK_ALL) != 0u || c->theta_margin_urad <= 0 || c->omega_max_urad_s <= 0 ||
      c->window_ms < 2u || c->window_ms > POUR_SUPERVISOR_WINDOW_MAX || c->torque_min <= 0 ||
      c->omega_against_urad_s <= 0 || c->against_ms < 1u || c->encoder_move_urad <= 0 || c->volume_step_max <= 0 ||
      c->accel_full_urad_s2 <= 0 || c->accel_passive_urad_s2 <= 0 ||
      theta_max_urad <= theta_min_urad) {
    return POUR_EINVAL;
  }
  sup->config = *c;
  sup->passive_term = (int64_t)c->accel_passive_urad_s2 * c->window_ms * 32768;
  sup->theta_low_urad = pour_sat_i32((int64_t)theta_min_urad - c->theta_margin_urad);
  sup->theta_high_urad = pour_sat_i32((int64_t)theta_max_urad + c->theta_margin_urad);
  pour_supervisor_restart(sup);
  return POUR_OK;
}

void pour_supervisor_restart(pour_supervisor_t *sup) {
  sup->head = 0u;
  sup->filled = 0u;
  sup->sum = 0;
  sup->sum_abs = 0;
  sup->against = 0u;
  sup->over = 0u;
  sup->have_state = false;
  sup->ticks_since_state = 0u;
  sup->seq_repeats = 0u;
}

bool pour_supervisor_accept(pour_supervisor_t *sup, const pour_state_t *state) {
  if (!sup->have_state || (sup->config.checks & POUR_CHECK_SEQ) == 0u) {
    return true;
  }
  const uint32_t advance = state->seq - sup->last.seq; /* unsigned: wraps by definition */
  if (advance >= 1u && advance <= SEQ_ADVANCE_MAX) {
    sup->last.seq = state->seq; /* also outside RUN (no step there): a long FAULT must not lose the count */
    return true;
  }
  if (sup->seq_repeats != UINT32_MAX) {
    sup->seq_repeats++;
  }
  return false;
}

static int32_t abs_q15_diff(q15_t a, q15_t b) {
  const int32_t d = (int32_t)a - b;
  return d < 0 ? -d : d;
}

static bool volume_jumped(const pour_supervisor_t *sup, const pour_state_t *s) {
  const uint32_t gap = sup->ticks_since_state < VOLUME_GAP_MAX ? sup->ticks_since_state : VOLUME_GAP_MAX;
  const int32_t allowed = (int32_t)sup->config.volume_step_max * (int32_t)(gap > 0u ? gap : 1u);
  const pour_state_t *l = &sup->last;
  return abs_q15_diff(s->v_rotating, l->v_rotating) > allowed || abs_q15_diff(s->v_target, l->v_target) > allowed ||
         abs_q15_diff(s->v_spill, l->v_spill) > allowed;
}

static uint8_t count_up(uint8_t n, bool yes) { return yes ? (n < UINT8_MAX ? (uint8_t)(n + 1u) : n) : 0u; }

static int32_t abs32(int32_t x) { return x < 0 ? -x : x; } /* callers pass differences of checked states */

/* TORQUE_SIGN, SCALE and ENCODER from the last W commands, in O(1): the ring's sums are kept as entries come
 * and go. Under a mean torque beyond what gravity can resist, the bucket cannot move against it and speed
 * up that way (a motor or encoder of the wrong sign); no speed change can exceed what the commands give the
 * lightest load plus what gravity and the liquid add (a scale stuck high); a bucket under that torque one
 * way for the whole window cannot keep its encoder reading (a frozen encoder). States reaching here passed
 * the core's plausibility check (|θ| <= π, |θ̇| <= 50 rad/s): their differences fit in int32. */
static uint16_t window_faults(pour_supervisor_t *sup, const pour_state_t *s) {
  const pour_supervisor_config_t *c = &sup->config;
  const uint8_t w = c->window_ms;
  if (sup->filled < w) {
    return 0u;
  }
  const uint8_t o = sup->head; /* the oldest entry of a full ring: the state W ticks ago */
  const int32_t d_omega = s->omega_urad_s - sup->omega[o];
  const int32_t mean = sup->sum / (int32_t)w;
  uint16_t faults = 0u;
  if ((c->checks & POUR_CHECK_TORQUE_SIGN) != 0u) {
    const int32_t dir = mean >= c->torque_min ? 1 : (mean <= -c->torque_min ? -1 : 0);
    const bool against = dir != 0 && -dir * s->omega_urad_s > c->omega_against_urad_s && -dir * d_omega > 0;
    sup->against = count_up(sup->against, against);
    if (sup->against >= c->against_ms) {
      faults |= POUR_FAULT_TORQUE_SIGN;
    }
  }
  if ((c->checks & POUR_CHECK_SCALE) != 0u) {
    /* |Δθ̇| [µrad/s] > (a_full · Σ|τ|/32768 + a_passive · W) / 1000, multiplied out (no division):
     * 32768000 · 5e7 and 3.5e8 · 10 · 32768 both fit int64. */
    const int64_t lhs = (int64_t)abs32(d_omega) * 32768000;
    const int64_t rhs = (int64_t)c->accel_full_urad_s2 * sup->sum_abs + sup->passive_term;
    sup->over = count_up(sup->over, lhs > rhs);
    if (sup->over >= c->against_ms) {
      faults |= POUR_FAULT_SCALE;
    }
  }
  /* One direction for the whole window (|Σ| = Σ|τ|) with a mean beyond what gravity resists. */
  if ((c->checks & POUR_CHECK_ENCODER) != 0u && (mean >= c->torque_min || mean <= -c->torque_min) &&
      abs32(sup->sum) == sup->sum_abs && abs32(s->theta_urad - sup->theta[o]) <= c->encoder_move_urad) {
    faults |= POUR_FAULT_ENCODER;
  }
  return faults;
}

uint16_t pour_supervisor_step(pour_supervisor_t *sup, const pour_state_t *state, bool fresh) {
  if (sup->ticks_since_state != UINT32_MAX) {
    sup->ticks_since_state++;
  }
  if (!fresh) {
    return 0u; /* a repeated state is no new evidence */
  }
  const pour_supervisor_config_t *c = &sup->config;
  uint16_t faults = 0u;
  if ((c->checks & POUR_CHECK_POSITION) != 0u &&
      (state->theta_urad < sup->theta_low_urad || state->theta_urad > sup->theta_high_urad)) {
    faults |= POUR_FAULT_POSITION;
  }
  if ((c->checks & POUR_CHECK_OVERSPEED) != 0u && abs32(state->omega_urad_s) > c->omega_max_urad_s) {
    faults |= POUR_FAULT_OVERSPEED;
  }
  if ((c->checks & POUR_CHECK_VOLUME) != 0u && sup->have_state && volume_jumped(sup, state)) {
    faults |= POUR_FAULT_VOLUME;
  }
  faults |= window_faults(sup, state);
  sup->last = *state;
  sup->have_state = true;
  sup->ticks_since_state = 0u;
  sup->seq_repeats = 0u;
  return faults;
}

void pour_supervisor_record(pour_supervisor_t *sup, const pour_state_t *state, q15_t torque) {
  const uint8_t w = sup->config.window_ms;
  if (sup->filled == w) { /* the oldest leaves the sums */
    const int32_t old = sup->torque[sup->head];
    sup->sum -= old;
    sup->sum_abs -= old < 0 ? -old : old;
  }
  sup->sum += torque;
  sup->sum_abs += torque < 0 ? -(int32_t)torque : torque;
  sup->torque[sup->head] = torque;
  sup->theta[sup->head] = state->theta_urad;
  sup->omega[sup->head] = state->omega_urad_s;
  sup->head = (uint8_t)(sup->head + 1u == w ? 0u : sup->head + 1u);
  if (sup->filled < w) {
    sup->filled++;
  }
}
