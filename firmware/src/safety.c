/* SPDX-License-Identifier: MIT */
#include "pour/safety.h"

#include <stddef.h>

/* docs/safety.md gives the reasons for each default. */
#define DEFAULT_SLEW_PER_TICK 3277        /* a full -1 -> +1 swing (65535 LSB) in 20 ticks */
#define DEFAULT_THETA_MIN_URAD (-87266)   /* -5 deg: a little past upright, never backwards over */
#define DEFAULT_THETA_MAX_URAD 2356194    /* 135 deg: the hard stop of the bucket's tilt */

pour_safety_config_t pour_safety_default_config(void) {
  pour_safety_config_t config;
  config.tau_limit = POUR_Q15_MAX;
  config.slew_per_tick = DEFAULT_SLEW_PER_TICK;
  config.theta_min_urad = DEFAULT_THETA_MIN_URAD;
  config.theta_max_urad = DEFAULT_THETA_MAX_URAD;
  return config;
}

pour_status_t pour_safety_init(pour_safety_t *safety, const pour_safety_config_t *config) {
  if (safety == NULL || config == NULL) {
    return POUR_EINVAL;
  }
  if (config->tau_limit <= 0 || config->slew_per_tick <= 0 || config->theta_max_urad <= config->theta_min_urad) {
    return POUR_EINVAL;
  }
  safety->config = *config;
  safety->torque = 0;
  safety->active = 0u;
  return POUR_OK;
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

q15_t pour_safety_apply(pour_safety_t *safety, q15_t requested, int32_t theta_urad) {
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
  const int32_t delta = cmd - (int32_t)safety->torque; /* |delta| < 2^16: no overflow */
  if (delta > c->slew_per_tick) {
    cmd = safety->torque + c->slew_per_tick;
    active |= POUR_LIMIT_SLEW;
  } else if (delta < -(int32_t)c->slew_per_tick) {
    cmd = safety->torque - c->slew_per_tick;
    active |= POUR_LIMIT_SLEW;
  }
  /* A slewed command can still carry the old sign past a limit: cut it now, since dropping to zero
   * torque never has to wait for the slew. */
  cmd = angle_cut(c, (q15_t)cmd, theta_urad, &active);
  safety->torque = (q15_t)cmd;
  safety->active = active;
  return safety->torque;
}

void pour_safety_force(pour_safety_t *safety, q15_t torque) {
  safety->torque = torque;
  safety->active = 0u;
}
