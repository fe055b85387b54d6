/* SPDX-License-Identifier: MIT */
#include "protect.h"

#include <stddef.h>

/* Faults after which the current loop and the angle sensors still work: the bucket is stopped actively. */
#define TRUSTED_FAULTS (POUR_DRIVE_FAULT_UNDERVOLTAGE | POUR_DRIVE_FAULT_OVERTEMP)

pour_protect_config_t pour_protect_default_config(void) {
  pour_protect_config_t c;
  c.uv_fault_mv = 18000u;
  c.uv_derate_mv = 20000u;
  c.ov_derate_mv = 26000u;
  c.ov_fault_mv = 28000u;
  c.temp_derate_mdegc = 80000;
  c.temp_fault_mdegc = 100000;
  c.bus_fault_ticks = 3u;
  c.backlash_urad = 17453; /* 1° */
  c.mismatch_ticks = 3u;
  c.brake_engage_ms = 30u;
  return c;
}

pour_status_t pour_protect_init(pour_protect_t *p, const pour_protect_config_t *c) {
  if (p == NULL || c == NULL || c->uv_fault_mv >= c->uv_derate_mv || c->uv_derate_mv >= c->ov_derate_mv ||
      c->ov_derate_mv >= c->ov_fault_mv || c->temp_derate_mdegc >= c->temp_fault_mdegc || c->bus_fault_ticks == 0u ||
      c->mismatch_ticks == 0u || c->backlash_urad <= 0) {
    return POUR_EINVAL;
  }
  const pour_protect_t zero = {0};
  *p = zero;
  p->config = *c;
  p->trusted = true;
  return POUR_OK;
}

/* (x - lo) / (hi - lo) in Q15, clamped to 0 .. 1.0. */
static q15_t ramp_q15(int64_t x, int64_t lo, int64_t hi) {
  if (x <= lo) {
    return 0;
  }
  if (x >= hi) {
    return POUR_Q15_MAX;
  }
  return (q15_t)(((x - lo) * POUR_Q15_MAX) / (hi - lo));
}

static q15_t min_q15(q15_t a, q15_t b) { return a < b ? a : b; }

static uint16_t count(uint16_t n, bool beyond) { return beyond ? (uint16_t)(n < 0xFFFFu ? n + 1u : n) : 0u; }

static int32_t abs_diff(int32_t a, int32_t b) {
  const int64_t d = (int64_t)a - b;
  return d < 0 ? (d < -INT32_MAX ? INT32_MAX : (int32_t)-d) : (d > INT32_MAX ? INT32_MAX : (int32_t)d);
}

void pour_protect_step(pour_protect_t *p, const pour_protect_input_t *in, pour_protect_output_t *out) {
  const pour_protect_config_t *c = &p->config;
  p->uv_ticks = count(p->uv_ticks, in->vbus_mv < c->uv_fault_mv);
  p->ov_ticks = count(p->ov_ticks, in->vbus_mv > c->ov_fault_mv);
  if (in->output_fresh) {
    if (!p->anchored) { /* the output encoder gives the absolute angle at start-up */
      p->anchor_urad = (int32_t)((int64_t)in->output_urad - in->motor_urad);
      p->anchored = true;
    }
    const int32_t from_motor = (int32_t)((int64_t)in->motor_urad + p->anchor_urad);
    p->mismatch_n = count(p->mismatch_n, abs_diff(from_motor, in->output_urad) > c->backlash_urad);
  }

  uint16_t now = 0u;
  now |= p->uv_ticks >= c->bus_fault_ticks ? POUR_DRIVE_FAULT_UNDERVOLTAGE : 0u;
  now |= p->ov_ticks >= c->bus_fault_ticks ? POUR_DRIVE_FAULT_OVERVOLTAGE : 0u;
  now |= in->temp_mdegc >= c->temp_fault_mdegc ? POUR_DRIVE_FAULT_OVERTEMP : 0u;
  now |= in->hw_overcurrent ? POUR_DRIVE_FAULT_HW_OVERCURRENT : 0u;
  now |= p->mismatch_n >= c->mismatch_ticks ? POUR_DRIVE_FAULT_ENCODER_MISMATCH : 0u;
  now |= in->calibration_valid ? 0u : POUR_DRIVE_FAULT_CALIBRATION;
  now |= in->loop_faults & POUR_DRIVE_FAULT_ALL;

  if (in->clear && now == 0u) {
    p->faults = 0u;
    p->trusted = true;
    p->anchored = false; /* re-anchor on the next fresh sample: the sensors agree again */
    p->mismatch_n = 0u;
  }
  if (p->faults == 0u && now != 0u) {
    p->since_fault_ms = 0u;
  }
  p->faults |= now;
  if ((p->faults & (uint16_t)~TRUSTED_FAULTS) != 0u || in->loop_faults != 0u) {
    p->trusted = false; /* once not trusted, for the rest of this stop */
  }

  out->torque_scale = min_q15(min_q15(ramp_q15(in->vbus_mv, c->uv_fault_mv, c->uv_derate_mv),
                                      ramp_q15(-(int64_t)in->vbus_mv, -(int64_t)c->ov_fault_mv, -(int64_t)c->ov_derate_mv)),
                              ramp_q15(-(int64_t)in->temp_mdegc, -(int64_t)c->temp_fault_mdegc, -(int64_t)c->temp_derate_mdegc));
  out->faults = p->faults;
  out->brake = p->faults != 0u;
  if (p->faults != 0u) {
    out->torque_scale = POUR_Q15_MAX; /* the stop gets what the drive still has: a derating would drop the bucket */
  }
  if (p->faults == 0u) {
    out->action = POUR_PROTECT_RUN;
  } else if (p->since_fault_ms >= c->brake_engage_ms || p->faults == POUR_DRIVE_FAULT_CALIBRATION) {
    out->action = POUR_PROTECT_HELD; /* an uncalibrated drive never ran: the brake was never released */
  } else {
    out->action = p->trusted ? POUR_PROTECT_ACTIVE_STOP : POUR_PROTECT_SHORT;
    p->since_fault_ms++;
  }
}
