/* SPDX-License-Identifier: MIT */
/* The motor drive: field-oriented current control of a PMSM at the PWM rate (pour_drive_isr), fed by the
 * 1 kHz step's torque (pour_drive_tick). Current sensing with start-up offsets, PI current loops on d and
 * q, the voltage vector limited to the bus, min–max modulation with dead-time compensation, a current
 * limit, an I²t limit, flux braking that keeps regenerated energy off the bus, and the drive's faults
 * (pour/drive_faults.h), each latched with the phases shorted (all low sides on) and the brake requested.
 * Fixed point, no float, no malloc, no I/O. Currents and voltages are per-unit Q15 of the bases below. */
#ifndef POUR_DRIVE_H
#define POUR_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/current_pi.h"
#include "pour/current_sense.h"
#include "pour/drive_faults.h"
#include "pour/fixed.h"
#include "pour/foc.h"
#include "pour/motor_cal.h"

#define POUR_DRIVE_I_BASE_MA 64000 /* current of Q15 1.0 [mA]: one LSB = 1.95 mA, ±64 A */
#define POUR_DRIVE_V_BASE_MV 64000 /* voltage of Q15 1.0 [mV]: one LSB = 1.95 mV, ±64 V */
#define POUR_DRIVE_BANDWIDTH_DIVISOR 20 /* ωc <= 2π·f_pwm / 20 (delay of 1.5 periods costs <= 27° of margin) */

/* Limit flags (pour_drive_output_t.limits): what shaped this period's output. */
#define POUR_DRIVE_LIMIT_CURRENT 0x01u    /* the q reference was clamped to the current limit */
#define POUR_DRIVE_LIMIT_VOLTAGE 0x02u    /* the voltage vector was cut to what the bus gives */
#define POUR_DRIVE_LIMIT_FLUX_BRAKE 0x04u /* the bus is high: d current dissipates regenerated energy */
#define POUR_DRIVE_LIMIT_I2T 0x08u        /* the I²t budget is more than half spent */

typedef enum {
  POUR_DRIVE_CALIBRATING = 0, /* PWM off, measuring the current offsets */
  POUR_DRIVE_RUN = 1,         /* the current loop runs */
  POUR_DRIVE_FAULTED = 2,     /* latched: phases shorted (low sides on), brake engaged */
  POUR_DRIVE_MEASURING = 3    /* the self-calibration (pour/motor_cal.h) drives the bridge, brake released */
} pour_drive_state_t;

typedef struct {
  /* power stage */
  uint32_t pwm_hz;             /* PWM and current-loop rate [Hz], 16,000..40,000 */
  uint32_t timer_clock_hz;     /* TIM1 clock [Hz]; centre-aligned period = clock / (2·pwm_hz) counts */
  uint32_t deadtime_ns;        /* dead time of each leg [ns], < 5 % of the period */
  /* motor and gearbox */
  uint32_t r_phase_uohm;       /* phase resistance [µΩ], 10 mΩ..10 Ω */
  uint32_t ld_nh;              /* d inductance [nH], 10 µH..10 mH */
  uint32_t lq_nh;              /* q inductance [nH], 10 µH..10 mH */
  uint32_t kt_unm_per_a;       /* torque per q current amplitude [µN·m/A], 1..1,000,000 */
  uint32_t pole_pairs;         /* 1..32 */
  uint32_t gear_ratio;         /* motor turns per output turn, 1..1000 */
  uint32_t gear_efficiency_q15; /* gearbox efficiency, Q15, 0.5..1.0 */
  /* current loop */
  uint32_t bandwidth_rad_s;    /* current-loop bandwidth ωc [rad/s], at most 2π·pwm_hz/20 */
  uint32_t current_limit_ma;   /* |i| ceiling of the references [mA] */
  uint32_t overcurrent_ma;     /* a phase current above this trips [mA], > current_limit_ma, < 64 A */
  uint32_t i_cont_ma;          /* continuous current: I²t accrues above it [mA] */
  uint32_t i2t_budget_a2s;     /* ∫(i² − i_cont²)dt that trips POUR_DRIVE_FAULT_I2T [A²·s] */
  /* DC bus */
  uint32_t vbus_ov_mv;         /* overvoltage trip [mV] */
  uint32_t vbus_uv_mv;         /* undervoltage trip [mV] (checked once running) */
  uint32_t regen_on_mv;        /* flux braking starts above this bus voltage [mV] */
  uint32_t regen_full_mv;      /* full flux-braking current at and above this [mV] */
  uint32_t flux_brake_ma;      /* d current at regen_full_mv [mA], <= current_limit_ma */
  uint32_t regen_enabled;      /* 1: flux braking on; 0: off (the bus then takes all regenerated energy) */
  /* sensing */
  uint32_t shunt_uohm;         /* phase shunt [µΩ] */
  uint32_t amp_gain_milli;     /* shunt amplifier gain [1/1000] */
  uint32_t adc_vref_mv;        /* ADC full scale [mV] (12-bit) */
  uint16_t offset_nominal;     /* amplifier bias at zero current [counts] */
  uint16_t offset_tolerance;   /* largest accepted offset error at start-up [counts] */
  uint32_t vbus_divider_milli; /* bus voltage / ADC pin voltage [1/1000] */
  uint32_t encoder_cpr;        /* motor encoder counts a turn, a power of two, 256..65536 */
  uint16_t encoder_offset;     /* electrical angle at count 0 (alignment), 65536 = 2π */
  uint32_t encoder_reversed;   /* 1: the count falls as the electrical angle rises; 0: it rises */
  uint32_t phase_sum_ma;       /* |ia + ib + ic| above this: a phase shorted to a rail or a bad shunt [mA] */
  uint32_t phase_loss_ms;      /* the loop saturated and its error above 1/4 of a reference above 1/10 of the
                                  limit this long: a phase open [ms] */
  uint32_t encoder_check_urad; /* output motion over which the motor encoder's direction is compared [µrad]:
                                  small, because a reversed encoder stalls the motor within a pole pitch */
  /* self-calibration (pour_drive_calibrate) */
  uint32_t cal_current_ma;     /* test current [mA], 100 .. current_limit_ma */
  uint32_t cal_l_test_mv;      /* square-wave amplitude of the inductance stage [mV], 100 .. 10,000 */
  uint32_t cal_motion_urad;    /* largest output motion the sequence may make [µrad], beyond it it stops;
                                  at least an electrical turn of a 32-pole-pair motor through the gear */
} pour_drive_config_t;

/* One sample, taken at the PWM's centre (counter underflow). */
typedef struct {
  uint16_t adc_phase[3]; /* shunt amplifier outputs [12-bit counts] */
  uint16_t adc_vbus;     /* bus divider [12-bit counts] */
  uint16_t encoder;      /* motor encoder timer count, modulo encoder_cpr */
} pour_drive_sample_t;

/* What the period's interrupt hands to the timer and reports. */
typedef struct {
  uint16_t compare[3]; /* TIM1 CCR1..3 for the next period, 0..period (0: low side on all period) */
  uint8_t pwm_enable;  /* 0: all six switches off (calibration); 1: the compares drive the bridge */
  uint8_t brake;       /* 1: engage the holding brake */
  q15_t id, iq;        /* measured d and q currents, per-unit */
  q15_t id_ref, iq_ref; /* their references, per-unit */
  q15_t vbus;          /* measured bus voltage, per-unit */
  int32_t duty[3];     /* duties, Q15 (compare = duty·period) */
  uint16_t limits;     /* POUR_DRIVE_LIMIT_* */
  uint16_t faults;     /* POUR_DRIVE_FAULT_* latched so far */
} pour_drive_output_t;

typedef struct {
  pour_drive_config_t config;
  pour_current_sense_t sense;
  pour_current_pi_t pi_d, pi_q;
  pour_foc_modulation_t modulation;
  pour_drive_state_t state;
  uint16_t period;            /* timer period [counts] */
  uint16_t faults;
  int32_t vbus_gain_q16;      /* per-unit bus voltage per ADC count, Q16 */
  int32_t torque_to_iq_q16;   /* per-unit q current per mN·m at the output, Q16 */
  int32_t limit_q15, overcurrent_q15, phase_sum_q15, flux_brake_q15;
  int32_t regen_on_q15, regen_span_q15, ov_q15, uv_q15;
  int32_t iq_cmd_q15;         /* from the last tick */
  q15_t vbus_q15;             /* the bus voltage of the last period held FAULTED, per-unit (for a clear) */
  uint8_t elec_shift;         /* 16 − log2(encoder_cpr) */
  uint16_t last_encoder;
  int32_t motor_counts;       /* motor encoder motion since the direction window opened [counts] */
  int32_t output_urad;        /* output motion over the same window [µrad] */
  int64_t i2_sum_q30;         /* Σ(id² + iq²) over this tick's periods */
  uint32_t i2_n;
  int64_t heat_q30ms;         /* ∫(i² − i_cont²)dt, per-unit Q30 · ms */
  int64_t i2t_budget_q30ms, i_cont2_q30;
  uint32_t phase_loss_count, phase_loss_limit; /* periods of lost current control, and the trip count */
  pour_motor_cal_t cal;               /* the self-calibration's state while MEASURING */
  pour_motor_cal_status_t cal_status; /* how the last one went (NONE since init, until one is started) */
  pour_motor_cal_result_t cal_result; /* its results, when cal_status is OK */
} pour_drive_t;

/* The B-G431B-ESC1 (3 mΩ shunts, 20 kHz) with a maxon EC 45 flat 70 W 24 V on the rig's 1:20 planetary
 * gearhead (docs/motor.md: every number and its source). */
pour_drive_config_t pour_drive_default_config(void);

/* Checks every field (POUR_EINVAL names nothing: pour_drive_config_check says which); starts the offset
 * calibration with the PWM off. */
pour_status_t pour_drive_init(pour_drive_t *drv, const pour_drive_config_t *config);

/* The first field of config out of range, or NULL if it is valid. */
const char *pour_drive_config_check(const pour_drive_config_t *config);

/* One PWM period, from the interrupt at the PWM centre. Never fails: faults latch in out->faults. */
void pour_drive_isr(pour_drive_t *drv, const pour_drive_sample_t *in, pour_drive_output_t *out);

/* The 1 kHz step's command: torque at the output [mN·m] → q current reference (torque constant, gear ratio,
 * efficiency: τ/(N·η·Kt) motoring, τ·η/(N·Kt) braking, as the output's motion says), clamped to the current limit; the I²t budget; the motor encoder's direction against the
 * output's motion since the last tick output_delta_urad [µrad]. */
void pour_drive_tick(pour_drive_t *drv, int32_t torque_mnm, int32_t output_delta_urad);

/* Starts the self-calibration (pour/motor_cal.h) with the bucket empty: from RUN, or FAULTED with nothing
 * latched but POUR_DRIVE_FAULT_CLEARED_BY_CALIBRATION (no valid calibration, the last one failed, an encoder
 * fault) once the current offsets are measured; else POUR_EINVAL. The brake is released while it runs (3.1 s). Success applies the results to
 * the configuration (R, L, pole pairs, encoder direction and offset; the current loop's gains from R and L),
 * the brake requested for that period, then RUN at zero current; a failure or a fault latches
 * POUR_DRIVE_FAULT_CALIBRATION (phases shorted, brake engaged) with the reason in cal_status. Its current
 * accrues to the I²t budget as a torque's does (pour_drive_tick): spent, the sequence ends ABORTED with
 * POUR_DRIVE_FAULT_I2T. */
pour_status_t pour_drive_calibrate(pour_drive_t *drv);

/* Whether pour_drive_calibrate would start the sequence now. */
bool pour_drive_can_calibrate(const pour_drive_t *drv);

/* Ends a running self-calibration (a stop, the e-stop): cal_status ABORTED, POUR_DRIVE_FAULT_CALIBRATION
 * latched, the bucket held. Nothing if none runs. */
void pour_drive_calibrate_abort(pour_drive_t *drv);

/* How the last self-calibration went; *result (may be NULL) is written when OK. */
pour_motor_cal_status_t pour_drive_calibration(const pour_drive_t *drv, pour_motor_cal_result_t *result);

/* Latches a fault from outside the loop (the comparators' break input, an over-temperature). */
void pour_drive_trip(pour_drive_t *drv, uint16_t fault);

/* ClearErrors: clears the latched faults whose cause is judged gone (POUR_DRIVE_FAULT_CLEARABLE, with the
 * bus and I²t conditions there); with none left, FAULTED becomes RUN at zero current, the PI loops reset.
 * With POUR_DRIVE_FAULT_CURRENT_OFFSET latched it clears nothing yet: the offsets are measured again with the
 * gates off (CALIBRATING, 256 periods), and the fault clears there only if they are in range (then RUN, or
 * FAULTED while others stay latched); out of range it stays. Returns the faults still latched (0: cleared).
 * Nothing changes outside FAULTED. */
uint16_t pour_drive_clear_faults(pour_drive_t *drv);

#endif /* POUR_DRIVE_H */
