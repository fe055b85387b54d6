/* SPDX-License-Identifier: MIT */
#include "pour/current_sense.h"

#include <string.h>

#include "pour/board_facts.h"

#define ADC_MAX 4095

pour_status_t pour_current_sense_init(pour_current_sense_t *cs, const pour_current_sense_config_t *config) {
  if (cs == NULL || config == NULL || config->gain_q16 == 0 || config->offset_nominal > ADC_MAX ||
      config->offset_tolerance > ADC_MAX / 2)
    return POUR_EINVAL;
  memset(cs, 0, sizeof *cs);
  cs->config = *config;
  return POUR_OK;
}

int pour_current_sense_calibrate(pour_current_sense_t *cs, const uint16_t adc[3]) {
  if (cs->calibrated) return 1;
  for (int k = 0; k < 3; ++k) cs->sum[k] += adc[k];
  if (++cs->n < POUR_CURRENT_SENSE_CAL_SAMPLES) return 0;
  int ok = 1;
  for (int k = 0; k < 3; ++k) {
    const uint32_t mean = (cs->sum[k] + POUR_CURRENT_SENSE_CAL_SAMPLES / 2) / POUR_CURRENT_SENSE_CAL_SAMPLES;
    const int32_t dev = (int32_t)mean - (int32_t)cs->config.offset_nominal;
    cs->offset[k] = (uint16_t)mean;
    if (dev > cs->config.offset_tolerance || dev < -(int32_t)cs->config.offset_tolerance) ok = 0;
  }
  cs->calibrated = (uint8_t)ok;
  return ok ? 1 : -1;
}

void pour_current_sense_convert(const pour_current_sense_t *cs, const uint16_t adc[3], q15_t i[3]) {
  for (int k = 0; k < 3; ++k) {
    /* The board's amplifier falls as current flows into the motor (POUR_BOARD_CURRENT_SIGN). |count| < 2^16 and
     * gain < 2^31: |x| < 2^47, so x >> 16 fits int32 before the Q15 saturation. */
    const int32_t counts = (int32_t)adc[k] - (int32_t)cs->offset[k];
    const int64_t x = (int64_t)(POUR_BOARD_CURRENT_SIGN < 0 ? -counts : counts) * cs->config.gain_q16;
    i[k] = pour_sat_q15((int32_t)((x + (1 << 15)) >> 16));
  }
}
