/* SPDX-License-Identifier: MIT */
/* Phase-current sensing: ADC counts → per-unit Q15 amperes through the amplifier's gain and the offsets
 * measured at start-up with the PWM off (a broken amplifier shows as an offset out of range). */
#ifndef POUR_CURRENT_SENSE_H
#define POUR_CURRENT_SENSE_H

#include <stdint.h>

#include "pour/fixed.h"

#define POUR_CURRENT_SENSE_CAL_SAMPLES 256 /* samples averaged per phase for the offsets (12.8 ms at 20 kHz) */

typedef struct {
  int32_t gain_q16;           /* Q15 per-unit current per ADC count, Q16 (pour_drive computes it from the board) */
  uint16_t offset_nominal;    /* the amplifier's bias with no current [counts] */
  uint16_t offset_tolerance;  /* largest accepted |measured − nominal| offset [counts] */
} pour_current_sense_config_t;

typedef struct {
  pour_current_sense_config_t config;
  uint32_t sum[3];   /* offset calibration sums */
  uint16_t n;        /* samples summed so far */
  uint16_t offset[3]; /* measured offsets [counts] */
  uint8_t calibrated; /* 1 once the offsets are measured and accepted */
} pour_current_sense_t;

/* Starts a calibration (offsets unknown). POUR_EINVAL for a gain of 0 or a nominal/tolerance that does not
 * fit a 12-bit converter. */
pour_status_t pour_current_sense_init(pour_current_sense_t *cs, const pour_current_sense_config_t *config);

/* One sample of the three converters with the PWM off. Returns 0 while calibrating, 1 once the offsets
 * are accepted, −1 if an offset is out of range (then the phase stays uncalibrated: the caller latches
 * POUR_DRIVE_FAULT_CURRENT_OFFSET). */
int pour_current_sense_calibrate(pour_current_sense_t *cs, const uint16_t adc[3]);

/* Three ADC counts → three phase currents (Q15 per-unit, saturated), positive into the motor: the board's
 * sign (pour/board_facts.h: offset − count on the B-G431B-ESC1) × (count − offset)·gain, rounded. */
void pour_current_sense_convert(const pour_current_sense_t *cs, const uint16_t adc[3], q15_t i[3]);

#endif /* POUR_CURRENT_SENSE_H */
