/* SPDX-License-Identifier: MIT */
/* The torque envelope applied to every command: clamp, slew-rate limit, angle limits. */
#ifndef POUR_SAFETY_H
#define POUR_SAFETY_H

#include <stdint.h>

#include "pour/fixed.h"

/* Bits of pour_safety_t.active: which limit shaped the last command. */
#define POUR_LIMIT_CLAMP 0x01u     /* |torque| was cut to tau_limit */
#define POUR_LIMIT_SLEW 0x02u      /* the change was cut to slew_per_tick */
#define POUR_LIMIT_ANGLE_MAX 0x04u /* positive torque refused at or past theta_max */
#define POUR_LIMIT_ANGLE_MIN 0x08u /* negative torque refused at or below theta_min */

typedef struct {
  q15_t tau_limit;         /* |torque| <= tau_limit, fraction of tau_max Q15, > 0 */
  q15_t slew_per_tick;     /* |torque change| per 1 ms tick, Q15, > 0 */
  int32_t theta_min_urad;  /* no torque that tilts further back at or below this [µrad] */
  int32_t theta_max_urad;  /* no torque that tilts further forward at or past this [µrad] */
} pour_safety_config_t;

typedef struct {
  pour_safety_config_t config;
  q15_t torque;   /* last commanded torque, Q15 */
  uint8_t active; /* POUR_LIMIT_* bits of the last command */
} pour_safety_t;

/* Defaults for the bench rig (docs/safety.md). */
pour_safety_config_t pour_safety_default_config(void);

/* Validates the config; the envelope starts at zero torque. */
pour_status_t pour_safety_init(pour_safety_t *safety, const pour_safety_config_t *config);

/* Shapes a requested torque by angle limits, then clamp, then slew; returns the command. */
q15_t pour_safety_apply(pour_safety_t *safety, q15_t requested, int32_t theta_urad);

/* Sets the command at once, bypassing the slew limit (e-stop and faults must not wait). */
void pour_safety_force(pour_safety_t *safety, q15_t torque);

#endif /* POUR_SAFETY_H */
