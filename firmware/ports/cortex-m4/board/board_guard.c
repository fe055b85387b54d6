/* SPDX-License-Identifier: MIT */
#include "board_guard.h"

#include <stddef.h>

#include "pour/board_facts.h"

#include "hal_brake.h"
#include "hal_drive.h"

#define TWO_PI_URAD 6283185LL

pour_guard_config_t pour_guard_default_config(void) {
  pour_guard_config_t c;
  c.adc_vref_mv = 3300u;
  c.vbus_divider_milli = 19170u;
  c.ntc_mv_at_t0 = POUR_BOARD_NTC_V0_MV; /* pour/board_facts.h: which of ST's two profiles, and why */
  c.ntc_t0_mdegc = 25000;
  c.ntc_uv_per_degc = POUR_BOARD_NTC_DV_DT_UV_PER_C;
  c.encoder_cpr = 4096u;
  c.gear_ratio = 20u;
  return c;
}

pour_status_t pour_guard_init(pour_guard_t *g, const pour_guard_config_t *config, const pour_protect_config_t *protect) {
  if (g == NULL || config == NULL || config->adc_vref_mv == 0u || config->vbus_divider_milli == 0u ||
      config->ntc_uv_per_degc <= 0 || config->encoder_cpr == 0u || config->gear_ratio == 0u) {
    return POUR_EINVAL;
  }
  const pour_guard_t zero = {0};
  *g = zero;
  g->config = *config;
  return pour_protect_init(&g->protect, protect);
}

void pour_guard_tick(pour_guard_t *g, const pour_hal_drive_sample_t *sample, uint16_t loop_faults, int32_t output_urad,
                     bool output_fresh, bool calibration_valid, bool clear, pour_protect_output_t *out) {
  const pour_guard_config_t *c = &g->config;
  if (sample != NULL) {
    const pour_hal_drive_sample_t *s = sample;
    const int64_t pin_mv = (int64_t)s->vbus * c->adc_vref_mv / 4096;
    g->vbus_mv = (uint32_t)(pin_mv * c->vbus_divider_milli / 1000);
    const int64_t ntc_mv = (int64_t)s->ntc * c->adc_vref_mv / 4096;
    g->temp_mdegc = (int32_t)(c->ntc_t0_mdegc + (ntc_mv - c->ntc_mv_at_t0) * 1000000 / c->ntc_uv_per_degc);
    if (g->sampled) {
      g->motor_counts += (int16_t)(uint16_t)(s->encoder - g->last_count); /* one tick moves < 2^15 counts */
    }
    g->last_count = s->encoder;
    g->sampled = true;
  }
  if (clear && pour_hal_drive_overcurrent_tripped()) {
    pour_hal_drive_clear_overcurrent(); /* the hardware fires again at once if a comparator still trips */
  }
  pour_protect_input_t in;
  in.vbus_mv = g->vbus_mv;
  in.temp_mdegc = g->temp_mdegc;
  in.hw_overcurrent = pour_hal_drive_overcurrent_tripped();
  in.motor_urad = (int32_t)(g->motor_counts * TWO_PI_URAD / ((int64_t)c->encoder_cpr * c->gear_ratio));
  in.output_urad = output_urad;
  in.output_fresh = output_fresh && g->sampled;
  in.calibration_valid = calibration_valid;
  in.loop_faults = loop_faults;
  in.clear = clear;
  pour_protect_step(&g->protect, &in, out);
  if (out->brake) {
    pour_hal_brake_set(true);
  }
}
