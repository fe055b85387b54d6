/* SPDX-License-Identifier: MIT */
/* The torque envelope applied to every command: clamp, slew-rate limit, angle limits, and the motion
 * envelope (a speed governor whose band widens at most at the acceleration limit), optionally scheduled by
 * the fill: a slow ceiling past a knee angle, with a feed-forward and an integral in its governor. */
#ifndef POUR_SAFETY_H
#define POUR_SAFETY_H

#include <stdint.h>

#include "pour/fixed.h"

/* Bits of pour_safety_t.active: which limit shaped the last command. */
#define POUR_LIMIT_CLAMP 0x01u     /* |torque| was cut to tau_limit */
#define POUR_LIMIT_SLEW 0x02u      /* the change was cut to slew_per_tick */
#define POUR_LIMIT_ANGLE_MAX 0x04u /* positive torque refused at or past theta_max */
#define POUR_LIMIT_ANGLE_MIN 0x08u /* negative torque refused at or below theta_min */
#define POUR_LIMIT_SPEED 0x10u     /* the governor cut the torque at the speed limit ±omega_max */
#define POUR_LIMIT_ACCEL 0x20u     /* the governor cut it at a speed band still ramping at alpha_max */
#define POUR_SAFETY_OMEGA_MAX_URAD_S 100000000 /* speeds the envelope works with, saturated: 100 rad/s */
#define POUR_SAFETY_KNEE_MAX_URAD 3141593       /* the fill schedule's knee: at most π */
#define POUR_SAFETY_DECEL_MAX_URAD_S2 1000000000 /* and its braking curve at most 1000 rad/s² */

typedef struct {
  q15_t tau_limit;         /* |torque| <= tau_limit, fraction of tau_max Q15, > 0 */
  q15_t slew_per_tick;     /* |torque change| per 1 ms tick, Q15, > 0 */
  int32_t theta_min_urad;  /* no torque that tilts further back at or below this [µrad] */
  int32_t theta_max_urad;  /* no torque that tilts further forward at or past this [µrad] */
  int32_t omega_max_urad_s;   /* speed limit: no torque that speeds |θ̇| up beyond it [µrad/s], > 0 */
  int32_t alpha_max_urad_s2;  /* the speed band widens at most this fast [µrad/s²], >= 1000 */
  int32_t omega_slack_urad_s; /* the band reaches this far beyond the current speed [µrad/s], > 0 */
  q15_t governor_gain;        /* torque bound per rad/s of speed margin, Q15 per rad/s, > 0 */
  /* The fill schedule (docs/safety.md, "Fill schedule"): off while knee_theta_urad is 0. */
  int32_t knee_theta_urad;    /* past this tilt the ceiling is slow_omega [µrad], 0 (off) .. KNEE_MAX */
  int32_t slow_omega_urad_s;  /* the ceiling past the knee (at most omega_max) [µrad/s], 1 .. OMEGA_MAX */
  int32_t knee_decel_urad_s2; /* before the knee the ceiling falls along this braking curve [µrad/s²], 1000 .. DECEL_MAX */
  q15_t slow_torque_ff;       /* past the knee the bound carries this feed-forward, Q15, >= 0 */
  uint16_t slow_ki_per_s;     /* and K · ki · ∫(ceiling - θ̇)dt, held within 0 .. tau_limit / 2 [1/s], 0: none */
} pour_safety_config_t;

typedef struct {
  pour_safety_config_t config;
  q15_t torque;   /* last commanded torque, Q15 */
  uint8_t active; /* POUR_LIMIT_* bits of the last command */
  int32_t alpha_step_urad_s;  /* alpha_max · 1 ms: the band's widening per tick [µrad/s] */
  int32_t gain_q32;           /* governor_gain / 10^6: Q15 torque per µrad/s, Q32 (< 2^28) */
  int32_t ceiling_urad_s;     /* speed band: no torque that speeds θ̇ beyond [floor, ceiling] [µrad/s] */
  int32_t floor_urad_s;
  int32_t integral_mq15;      /* the fill schedule's integral [Q15 / 1000], 0 .. tau_limit · 500 */
} pour_safety_t;

/* Defaults for the bench rig (docs/safety.md). */
pour_safety_config_t pour_safety_default_config(void);

/* Validates the config; the envelope starts at zero torque, its speed band at ±omega_slack (at rest). */
pour_status_t pour_safety_init(pour_safety_t *safety, const pour_safety_config_t *config);

/* The envelope's run state as pour_safety_init leaves it (zero torque, no limit active, the governor's bounds and
 * integral from rest), its config and the values derived from it kept: what a Reset restarts, without init's
 * check and its two 64-bit divisions (~300 instructions on the Cortex-M4). */
void pour_safety_restart(pour_safety_t *safety);

/* Shapes a requested torque by angle limits, clamp, the speed band, slew, then cuts toward zero whatever still
 * lies beyond the band or an angle limit (less torque never waits for the slew). The band follows the
 * estimated speed omega_urad_s: ceiling = min(omega_max, ceiling + alpha step, max(θ̇, 0) + slack), floor
 * likewise, torque within [K (floor - θ̇), K (ceiling - θ̇)] (K = governor_gain, each bound within
 * ±tau_limit): beyond the band the bound changes sign and brakes, against gravity too. With a knee, the
 * ceiling is also at most sqrt(slow² + 2 · knee_decel · (knee - θ)) before the knee and slow past it; where
 * that limit is below omega_max the upper bound is min(K (ceiling - θ̇) + slow_torque_ff + I,
 * K (omega_max - θ̇)), I integrating K · ki · (ceiling - θ̇) while that bound cuts the request (or the speed
 * is above the ceiling), within 0 .. tau_limit / 2; elsewhere I is 0. Returns the command; safety->active
 * tells which rules shaped it. */
q15_t pour_safety_apply(pour_safety_t *safety, q15_t requested, int32_t theta_urad, int32_t omega_urad_s);

/* Sets the command at once, bypassing the slew limit (e-stop and faults must not wait). */
void pour_safety_force(pour_safety_t *safety, q15_t torque);

/* Moves the command toward a torque to hold without a step: there at once when it lies between zero and the
 * present command (less torque never waits), else by at most slew_per_tick (POUR_LIMIT_SLEW). Returns it. */
q15_t pour_safety_hold(pour_safety_t *safety, q15_t target);

#endif /* POUR_SAFETY_H */
