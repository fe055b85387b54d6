/* SPDX-License-Identifier: MIT */
#include "hal_drive_g4.h"

#include <stddef.h>

#include "encoder_tim4.h"
#include "hal_drive.h"

static pour_pwm_t pwm;
static pour_adc_t adc;
static volatile uint32_t *tim4;
static const pour_ocp_t *ocp;

void pour_hal_drive_attach(const pour_pwm_t *p, const pour_adc_t *a, volatile uint32_t *t, const pour_ocp_t *o) {
  pwm = *p;
  adc = *a;
  tim4 = t;
  ocp = o;
}

uint16_t pour_hal_drive_period(void) { return pwm.period; }

bool pour_hal_drive_sample(pour_hal_drive_sample_t *sample) {
  pour_adc_sample_t s;
  if (adc.adc1 == NULL || tim4 == NULL || !pour_adc_read(&adc, &s)) {
    return false;
  }
  for (unsigned i = 0; i < 3u; ++i) {
    sample->phase[i] = s.phase[i];
  }
  sample->vbus = s.vbus;
  sample->ntc = s.ntc;
  sample->encoder = pour_encoder_count(tim4);
  return true;
}

void pour_hal_drive_set_compares(const uint16_t compare[3]) {
  if (pwm.regs != NULL) {
    pour_pwm_set_compares(&pwm, compare);
  }
}

void pour_hal_drive_enable(bool on) {
  if (pwm.regs != NULL) {
    pour_pwm_enable(&pwm, on);
  }
}

void pour_hal_drive_short_low_sides(void) {
  if (pwm.regs != NULL) {
    pour_pwm_short_low_sides(&pwm);
  }
}

bool pour_hal_drive_overcurrent_tripped(void) { return pwm.regs != NULL && pour_pwm_break_fired(&pwm); }

void pour_hal_drive_clear_overcurrent(void) {
  /* MOE only once every comparator's output is low again: the break's cause gone, not merely masked */
  const bool tripping = ocp != NULL && ocp->comp != NULL && pour_ocp_tripping(ocp);
  if (pwm.regs != NULL && !tripping) {
    pour_pwm_clear_break(&pwm);
  }
}
