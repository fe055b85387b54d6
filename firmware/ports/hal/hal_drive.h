/* SPDX-License-Identifier: MIT */
/* hal_drive: the power stage as the motor library's current-loop interrupt sees it, once per PWM period:
 * read the sample taken at the centre of the period, write the next period's three compares, switch the
 * gates, short the low sides, and the hardware overcurrent cut. One implementation per port (Cortex-M4:
 * board_stm32g431.c over TIM1, ADC1/2, OPAMP1-3, COMP1/2/4 + DAC3, TIM4). */
#ifndef POUR_HAL_DRIVE_H
#define POUR_HAL_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"

typedef struct {
  uint16_t phase[3]; /* U, V, W shunt amplifier outputs [12-bit counts] */
  uint16_t vbus;     /* bus voltage divider [12-bit counts] */
  uint16_t ntc;      /* power-stage NTC divider [12-bit counts] */
  uint16_t encoder;  /* motor encoder count, modulo 2^16 */
} pour_hal_drive_sample_t;

/* PWM counting with all six switches off, the converters armed on its trigger, the amplifiers and the
 * encoder counter on. POUR_EINVAL if a peripheral does not come up (then the switches stay off). */
pour_status_t pour_hal_drive_init(void);

/* Timer counts from the bottom to the top of a period: the compares' full scale. */
uint16_t pour_hal_drive_period(void);

/* This period's sample: true once it is complete (then it is consumed), false before. */
bool pour_hal_drive_sample(pour_hal_drive_sample_t *sample);

/* Next period's compares, 0 .. period (0: the low side on all period). */
void pour_hal_drive_set_compares(const uint16_t compare[3]);

/* true: the gates follow the compares; false: all six switches off (current-offset calibration). */
void pour_hal_drive_enable(bool on);

/* All three low sides on at once: the phases shorted (damping; what a drive that is no longer trusted does
 * until the brake holds). */
void pour_hal_drive_short_low_sides(void);

/* Arms the hardware overcurrent cut with thresholds above the three measured zero-current readings
 * [counts]. POUR_EINVAL if a threshold does not fit (an offset far out of range). */
pour_status_t pour_hal_drive_arm_overcurrent(const uint16_t offset_counts[3]);

/* true once the hardware cut has fired (latched: the phases stay shorted) until cleared. */
bool pour_hal_drive_overcurrent_tripped(void);

/* ClearErrors: re-arms the cut with all six switches off once no comparator trips; while one does, the cut
 * stays fired. */
void pour_hal_drive_clear_overcurrent(void);

/* true: the current loop's interrupt is held off (the 1 kHz tick's short exchanges with the loop's state);
 * false: it runs again (a period that ended meanwhile is taken at once). */
void pour_hal_drive_mask(bool masked);

#endif /* POUR_HAL_DRIVE_H */
