/* SPDX-License-Identifier: MIT */
#include "pour/supervisor.h"

#include <stddef.h>

#include "pour/faults.h"
#include "pour/params.h"

/* docs/safety.md gives the reason for each default; the figures come from 20 held-out pours of the shipped
 * policy and 5 of the hand-written baseline in the simulator (tau_max 20 N·m, 10 kg of liquid), re-tuned for
 * the estimated θ̇, the motion envelope and the 80 Hz load cells (firmware 3). */
#define DEFAULT_WINDOW_MS 10u
#define DEFAULT_TORQUE_MIN 11469            /* 0.35 tau_max = 7 N·m, 30 % above the liquid's worst gravity torque */
#define DEFAULT_OMEGA_AGAINST_URAD_S 300000 /* 0.3 rad/s */
#define DEFAULT_AGAINST_MS 3u
#define DEFAULT_ENCODER_MOVE_URAD 200       /* 4 counts of 17 bits: above a count's jitter */
#define DEFAULT_ENCODER_MS 30u              /* 30 ms at >= 0.35 tau_max move even a turning bucket further */
#define DEFAULT_VOLUME_STEP_MAX 1966        /* 6 % of the liquid per tick since the reading last changed */
#define DEFAULT_ACCEL_FULL_URAD_S2 350000000    /* 350 rad/s²: 20 N·m on the empty bucket measured 335 */
#define DEFAULT_ACCEL_PASSIVE_URAD_S2 150000000 /* 150 rad/s²: nominal never beyond it 2 ticks in a row */
#define SEQ_ADVANCE_MAX 32767u              /* a forward gap larger than this is a jump back, not a gap */
#define DW_UNIT_URAD_S 32                   /* the ring keeps |Δθ̇| per tick in these units (uint16) */
#define VOLUME_GAP_MAX 16u                  /* ticks credited to a volume change, at most: an 80 Hz load cell
                                             * holds its reading 12.5 ms, 16 leave room for its jitter */

/* theta_margin_urad's and omega_max_urad_s's defaults are the declaration's rows of group supervisor
 * (POUR_PARAMS, pour/params.h); the other groups' live elsewhere. */
#define SUPERVISOR_ROW_safety(member, type, value)
#define SUPERVISOR_ROW_stop(member, type, value)
#define SUPERVISOR_ROW_sensors(member, type, value)
#define SUPERVISOR_ROW_supervisor(member, type, value) c.member = (type)(value);
#define SUPERVISOR_ROW_port(member, type, value)
#define SUPERVISOR_DEFAULT(id, name, unit, def, lo, hi, type, group, member, doc) \
  SUPERVISOR_ROW_##group(member, type, def)

pour_supervisor_config_t pour_supervisor_default_config(void) {
  pour_supervisor_config_t c;
  c.checks = POUR_CHECK_ALL;
  POUR_PARAMS(SUPERVISOR_DEFAULT)
  c.window_ms = DEFAULT_WINDOW_MS;
  c.torque_min = DEFAULT_TORQUE_MIN;
  c.omega_against_urad_s = DEFAULT_OMEGA_AGAINST_URAD_S;
  c.against_ms = DEFAULT_AGAINST_MS;
  c.encoder_move_urad = DEFAULT_ENCODER_MOVE_URAD;
  c.encoder_ms = DEFAULT_ENCODER_MS;
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
      c->omega_against_urad_s <= 0 || c->against_ms < 1u || c->encoder_move_urad <= 0 || c->encoder_ms < 1u ||
      c->volume_step_max <= 0 ||
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
  sup->sum_dw = 0;
  sup->against = 0u;
  sup->over = 0u;
  sup->still_ticks = 0u;
  sup->push_ticks = 0u;
  sup->push_dir = 0;
  sup->have_state = false;
  sup->ticks_since_volume = 0u;
  sup->seq_repeats = 0u;
}

bool pour_supervisor_accept(pour_supervisor_t *sup, uint32_t seq) {
  if (!sup->have_state || (sup->config.checks & POUR_CHECK_SEQ) == 0u) {
    return true;
  }
  const uint32_t advance = seq - sup->last_seq; /* unsigned: wraps by definition */
  if (advance >= 1u && advance <= SEQ_ADVANCE_MAX) {
    sup->last_seq = seq; /* also outside RUN (no step there): a long FAULT must not lose the count */
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

/* The load cells update at their own rate (80 Hz) and hold in between: a volume moves in steps. Each step is
 * judged against the time since the reading last changed, so a held reading does not look like a jump. */
static bool volume_jumped(const pour_supervisor_t *sup, const pour_state_t *s) {
  const uint32_t gap = sup->ticks_since_volume < VOLUME_GAP_MAX ? sup->ticks_since_volume : VOLUME_GAP_MAX;
  const int32_t allowed = (int32_t)sup->config.volume_step_max * (int32_t)(gap > 0u ? gap : 1u);
  return abs_q15_diff(s->v_rotating, sup->volume[0]) > allowed || abs_q15_diff(s->v_target, sup->volume[1]) > allowed ||
         abs_q15_diff(s->v_spill, sup->volume[2]) > allowed;
}

static bool volume_changed(const pour_supervisor_t *sup, const pour_state_t *s) {
  return s->v_rotating != sup->volume[0] || s->v_target != sup->volume[1] || s->v_spill != sup->volume[2];
}

static uint8_t count_up(uint8_t n, bool yes) { return yes ? (n < UINT8_MAX ? (uint8_t)(n + 1u) : n) : 0u; }

static uint16_t count_up16(uint16_t n) { return n < UINT16_MAX ? (uint16_t)(n + 1u) : n; }

static int32_t abs32(int32_t x) { return x < 0 ? -x : x; } /* callers pass differences of checked states */

/* TORQUE_SIGN and SCALE from the last W commands, in O(1): the ring's sums are kept as entries come and go.
 * Under a mean torque beyond what gravity can resist, the bucket cannot move against it and speed up that
 * way (a motor or encoder of the wrong sign); no speed change can exceed what the commands give the
 * lightest load plus what gravity and the liquid add (a scale stuck high). States reaching here passed the
 * core's plausibility check (|θ| <= π, |θ̇| <= 50 rad/s): their differences fit in int32. */
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
    /* The path of θ̇ over the window, Σ|Δθ̇| [µrad/s], not only its net change: under the speed band a torque
     * scale stuck high shows as a chatter whose swings cancel over the window (fault_pour, firmware 3).
     * Path > (a_full · Σ|τ|/32768 + a_passive · W) / 1000, multiplied out (no division): a path < 10^9
     * (|θ̇| <= 50 rad/s) times 32768000, and 3.5e8 · 10 · 32768, both fit int64. */
    const uint8_t newest = (uint8_t)(o == 0u ? w - 1u : o - 1u);
    const int32_t path =
        sup->sum_dw - (int32_t)sup->dw[o] * DW_UNIT_URAD_S + abs32(s->omega_urad_s - sup->omega[newest]);
    const int64_t lhs = (int64_t)path * 32768000;
    const int64_t rhs = (int64_t)c->accel_full_urad_s2 * sup->sum_abs + sup->passive_term;
    sup->over = count_up(sup->over, lhs > rhs);
    if (sup->over >= c->against_ms) {
      faults |= POUR_FAULT_SCALE;
    }
  }
  return faults;
}

/* ENCODER: θ has stayed within ±encoder_move of where it last was for encoder_ms samples while every
 * command of as many ticks was beyond what gravity can resist, one way. A window on the end-to-end
 * displacement would not do: a bucket turning round under such a torque comes back to where it was 10 ms
 * before, but it does not stay within a few counts for 30 ms (docs/safety.md). */
static bool encoder_frozen(pour_supervisor_t *sup, const pour_state_t *s) {
  const pour_supervisor_config_t *c = &sup->config;
  if (!sup->have_state || abs32(s->theta_urad - sup->still_theta_urad) > c->encoder_move_urad) {
    sup->still_theta_urad = s->theta_urad;
    sup->still_ticks = 0u;
  } else {
    sup->still_ticks = count_up16(sup->still_ticks);
  }
  return (c->checks & POUR_CHECK_ENCODER) != 0u && sup->still_ticks >= c->encoder_ms &&
         sup->push_ticks >= c->encoder_ms;
}

uint16_t pour_supervisor_step(pour_supervisor_t *sup, const pour_state_t *state, bool fresh) {
  if (sup->ticks_since_volume != UINT32_MAX) {
    sup->ticks_since_volume++;
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
  if (encoder_frozen(sup, state)) {
    faults |= POUR_FAULT_ENCODER;
  }
  if (!sup->have_state || volume_changed(sup, state)) {
    sup->volume[0] = state->v_rotating;
    sup->volume[1] = state->v_target;
    sup->volume[2] = state->v_spill;
    sup->ticks_since_volume = 0u;
  }
  sup->last_seq = state->seq;
  sup->have_state = true;
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
  if (sup->filled == w) {
    sup->sum_dw -= (int32_t)sup->dw[sup->head] * DW_UNIT_URAD_S;
  }
  const uint8_t prev = (uint8_t)(sup->head == 0u ? w - 1u : sup->head - 1u);
  int32_t dw = sup->filled > 0u ? abs32(state->omega_urad_s - sup->omega[prev]) / DW_UNIT_URAD_S : 0;
  dw = dw > UINT16_MAX ? UINT16_MAX : dw; /* 2.1 rad/s in a tick: beyond that the path saturates */
  sup->sum += torque;
  sup->sum_abs += torque < 0 ? -(int32_t)torque : torque;
  sup->sum_dw += dw * DW_UNIT_URAD_S;
  sup->torque[sup->head] = torque;
  sup->omega[sup->head] = state->omega_urad_s;
  sup->dw[sup->head] = (uint16_t)dw;
  const int32_t tmin = sup->config.torque_min;
  const int8_t dir = (int8_t)(torque >= tmin ? 1 : (torque <= -tmin ? -1 : 0));
  sup->push_ticks = dir == 0 ? 0u : (dir == sup->push_dir ? count_up16(sup->push_ticks) : 1u);
  sup->push_dir = dir;
  sup->head = (uint8_t)(sup->head + 1u == w ? 0u : sup->head + 1u);
  if (sup->filled < w) {
    sup->filled++;
  }
}
