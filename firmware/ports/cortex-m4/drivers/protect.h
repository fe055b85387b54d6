/* SPDX-License-Identifier: MIT */
/* The board's protection, once per 1 kHz tick, no I/O: bus under- and overvoltage and the power stage's
 * temperature derate the torque first, then fault; the hardware overcurrent cut, a disagreement of the two
 * angle sensors beyond the gearbox's backlash, and a missing calibration fault at once. Every fault is
 * latched in the drive's fault word (pour/drive_faults.h) and cleared only by ClearErrors once its cause is
 * gone. On a fault the brake is engaged at once and, until it holds, the bucket is stopped actively where
 * the drive is still trusted (undervoltage, over-temperature: the loop and the sensors work) or the
 * phases are shorted where it is not (overcurrent, overvoltage, sensors that disagree): never coasting. */
#ifndef POUR_PROTECT_H
#define POUR_PROTECT_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/drive_faults.h"
#include "pour/fixed.h"

typedef enum {
  POUR_PROTECT_RUN = 0,         /* no fault: the core's torque, scaled by the derating */
  POUR_PROTECT_ACTIVE_STOP = 1, /* a trusted drive holds the bucket where it is, the brake engaging */
  POUR_PROTECT_SHORT = 2,       /* all low sides on (damping), the brake engaging */
  POUR_PROTECT_HELD = 3         /* the brake holds: phases shorted, power may go off */
} pour_protect_action_t;

typedef struct {
  uint32_t uv_fault_mv, uv_derate_mv; /* undervoltage: full torque above derate, 0 and a fault below fault */
  uint32_t ov_derate_mv, ov_fault_mv; /* overvoltage: the same from above */
  int32_t temp_derate_mdegc, temp_fault_mdegc; /* power stage temperature [m°C] */
  uint16_t bus_fault_ticks;    /* a bus fault is this many consecutive ticks beyond its threshold, >= 1 */
  int32_t backlash_urad;       /* gearbox backlash plus the encoders' error: the sensors may disagree by this */
  uint16_t mismatch_ticks;     /* consecutive fresh disagreeing samples that are a fault, >= 1 */
  uint16_t brake_engage_ms;    /* the brake's engagement time: after it the brake holds */
} pour_protect_config_t;

typedef struct {
  uint32_t vbus_mv;          /* bus voltage [mV] */
  int32_t temp_mdegc;        /* power stage [m°C] */
  bool hw_overcurrent;       /* the comparators cut the PWM (TIM1 break) */
  int32_t motor_urad;        /* output angle from the motor encoder through the gear ratio [µrad] */
  int32_t output_urad;       /* the output shaft's absolute encoder [µrad] */
  bool output_fresh;         /* output_urad is a new sample this tick */
  bool calibration_valid;    /* a valid calibration block was loaded */
  uint16_t loop_faults;      /* POUR_DRIVE_FAULT_* the current loop latched itself: it shorts its phases */
  bool clear;                /* ClearErrors this tick */
} pour_protect_input_t;

typedef struct {
  q15_t torque_scale;           /* 0 .. 1.0: the derating of the core's torque */
  uint16_t faults;              /* POUR_DRIVE_FAULT_*, latched */
  pour_protect_action_t action;
  bool brake;                   /* engage the brake */
} pour_protect_output_t;

typedef struct {
  pour_protect_config_t config;
  uint16_t faults;
  uint16_t uv_ticks, ov_ticks, mismatch_n;
  uint32_t since_fault_ms; /* since the first of the latched faults */
  int32_t anchor_urad;     /* output - motor angle at the first fresh output sample */
  bool anchored;
  bool trusted;            /* every latched fault leaves the drive trusted */
} pour_protect_t;

/* B-G431B-ESC1 on a 6S bus: derate below 20 V, fault below 18 V; derate above 26 V, fault above 28 V;
 * derate from 80 °C, fault at 100 °C; backlash 1°; brake engaged within 30 ms. */
pour_protect_config_t pour_protect_default_config(void);

/* POUR_EINVAL for thresholds out of order or zero counts. */
pour_status_t pour_protect_init(pour_protect_t *p, const pour_protect_config_t *config);

void pour_protect_step(pour_protect_t *p, const pour_protect_input_t *in, pour_protect_output_t *out);

#endif /* POUR_PROTECT_H */
