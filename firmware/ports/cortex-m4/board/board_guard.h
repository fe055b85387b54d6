/* SPDX-License-Identifier: MIT */
/* The board's protection wired to its HAL, once per 1 kHz tick: the bus voltage, the NTC and the motor
 * encoder of the current loop's latest sample (hal_drive's, which the loop's interrupt takes), the hardware
 * overcurrent cut, pour_protect_step, and what it says: the brake (hal_brake) at once; the phases shorted,
 * unless the drive is still trusted to stop the bucket, are the caller's (board_drive: not while the drive
 * measures the motor). The output angle and ClearErrors come from the
 * bus; the calibration's validity from its storage. */
#ifndef POUR_BOARD_GUARD_H
#define POUR_BOARD_GUARD_H

#include <stdbool.h>
#include <stdint.h>

#include "hal_drive.h"
#include "protect.h"

typedef struct {
  uint32_t adc_vref_mv;        /* ADC full scale [mV] */
  uint32_t vbus_divider_milli; /* bus voltage / pin voltage [1/1000] */
  int32_t ntc_mv_at_t0;        /* NTC divider's pin voltage at t0 [mV] (linear model of the sensor) */
  int32_t ntc_t0_mdegc;        /* [m°C] */
  int32_t ntc_uv_per_degc;     /* slope [µV/°C], > 0: the pin voltage rises with temperature */
  uint32_t encoder_cpr;        /* motor encoder counts a motor turn (x4) */
  uint32_t gear_ratio;         /* motor turns per output turn */
} pour_guard_config_t;

typedef struct {
  pour_guard_config_t config;
  pour_protect_t protect;
  uint16_t last_count;
  int64_t motor_counts; /* unwrapped */
  uint32_t vbus_mv;
  int32_t temp_mdegc;
  bool sampled;
} pour_guard_t;

/* B-G431B-ESC1 (divider 19.17, NTC 1.055 V at 25 °C and 22.7 mV/°C as ST's profile of the board gives
 * them: to be checked at bring-up) with a 4096-count encoder on a 1:20 gearbox. */
pour_guard_config_t pour_guard_default_config(void);

pour_status_t pour_guard_init(pour_guard_t *g, const pour_guard_config_t *config, const pour_protect_config_t *protect);

/* One tick on the loop's latest sample (NULL: none since the last tick; the previous readings stand) and
 * the faults the loop latched itself (loop_faults, POUR_DRIVE_FAULT_*); *out says what was done (and, in
 * POUR_PROTECT_ACTIVE_STOP, that the caller's stop is to run). */
void pour_guard_tick(pour_guard_t *g, const pour_hal_drive_sample_t *sample, uint16_t loop_faults, int32_t output_urad,
                     bool output_fresh, bool calibration_valid, bool clear, pour_protect_output_t *out);

#endif /* POUR_BOARD_GUARD_H */
