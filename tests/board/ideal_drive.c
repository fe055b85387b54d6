/* SPDX-License-Identifier: MIT */
#include "ideal_drive.h"

#include "pour/board_facts.h"
#include "pour/foc.h"

#define HALF_SQRT3_Q15 28378

void pour_ideal_phase_counts(const pour_drive_t *drv, q15_t id, q15_t iq, uint16_t encoder, uint16_t bias,
                             uint16_t counts[3]) {
  const pour_drive_config_t *c = &drv->config;
  const uint16_t angle = (uint16_t)((((uint32_t)encoder * c->pole_pairs) << drv->elec_shift) + c->encoder_offset);
  q15_t s, co, alpha, beta;
  pour_foc_sincos_q15(angle, &s, &co);
  pour_foc_inv_park_q15(id, iq, s, co, &alpha, &beta);
  const int32_t b_part = (int32_t)(((int64_t)beta * HALF_SQRT3_Q15 + (1 << 14)) >> 15);
  const int32_t i[3] = {alpha, -alpha / 2 + b_part, -alpha / 2 - b_part};
  for (int k = 0; k < 3; ++k) {
    /* the board's amplifier (pour/board_facts.h): count = bias + sign x i / gain, rounded */
    const int64_t num = (int64_t)i[k] * 65536 * POUR_BOARD_CURRENT_SIGN;
    const int64_t g = drv->sense.config.gain_q16;
    const int64_t n = bias + (num >= 0 ? (num + g / 2) / g : (num - g / 2) / g);
    counts[k] = (uint16_t)(n < 0 ? 0 : (n > 4095 ? 4095 : n));
  }
}

int32_t pour_ideal_torque_mnm(const pour_drive_config_t *c, q15_t iq, bool motoring) {
  /* iq/32768 · I_BASE [mA] · Kt [µN·m/A] · N, in mN·m: / 1e6; then · η or / η (η = eff/32768) */
  const int64_t t = (int64_t)iq * POUR_DRIVE_I_BASE_MA * c->kt_unm_per_a * c->gear_ratio / 32768;
  const int64_t eff = c->gear_efficiency_q15;
  return (int32_t)(motoring ? t * eff / 32768 / 1000000 : t * 32768 / eff / 1000000);
}

uint16_t pour_ideal_adc_counts(const pour_drive_config_t *c, uint32_t pin_mv) {
  const uint32_t n = (pin_mv * 4096u + c->adc_vref_mv / 2u) / c->adc_vref_mv;
  return (uint16_t)(n > 4095u ? 4095u : n);
}
