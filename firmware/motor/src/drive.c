/* SPDX-License-Identifier: MIT */
#include "pour/drive.h"

#include <stddef.h>
#include <string.h>

#include "pour/board_facts.h"

#define I_BASE POUR_DRIVE_I_BASE_MA
#define V_BASE POUR_DRIVE_V_BASE_MV
#define VMAX_OF_BUS_Q15 17784 /* 0.94/√3: the min–max range less the dead-time and duty-ceiling margins */
#define DUTY_MAX_Q15 31130    /* 95 %: the low-side shunts need the low side on long enough to sample */
#define DEADTIME_BAND_MA 500  /* below this |i| the dead-time compensation ramps (its sign is noise there) */
#define TWO_PI_URAD 6283185

pour_drive_config_t pour_drive_default_config(void) {
  pour_drive_config_t c;
  memset(&c, 0, sizeof c);
  c.pwm_hz = 20000;
  c.timer_clock_hz = 170000000;
  c.deadtime_ns = POUR_BOARD_DEADTIME_NS;
  /* maxon EC 45 flat 70 W, 24 V (docs/motor.md): a star winding's phase is half the terminal values */
  c.r_phase_uohm = 286500; /* half the 0.573 Ω terminal resistance (phase to phase) */
  c.ld_nh = 150500;        /* half the 0.301 mH terminal inductance (iron-core, surface magnets: Ld = Lq) */
  c.lq_nh = 150500;
  c.kt_unm_per_a = 40400;
  c.pole_pairs = 8;
  c.gear_ratio = 20;
  c.gear_efficiency_q15 = 29491; /* 0.90 */
  c.bandwidth_rad_s = 3000;
  c.current_limit_ma = 36000;
  c.overcurrent_ma = 45000;
  c.i_cont_ma = 3290;       /* the motor's nominal (max. continuous) current */
  c.i2t_budget_a2s = 466;   /* I_n²·τ_w: 3.29² A² × the winding's 43.1 s thermal time constant */
  c.vbus_ov_mv = 28000;
  c.vbus_uv_mv = 10000;
  c.regen_on_mv = 24500;
  c.regen_full_mv = 25000;
  c.flux_brake_ma = 20000;
  c.regen_enabled = 1;
  c.shunt_uohm = POUR_BOARD_SHUNT_UOHM; /* the analog chain: pour/board_facts.h */
  c.amp_gain_milli = POUR_BOARD_AMP_GAIN_MILLI;
  c.adc_vref_mv = POUR_BOARD_ADC_VREF_MV;
  c.offset_nominal = POUR_BOARD_OFFSET_NOMINAL_COUNTS;
  c.offset_tolerance = POUR_BOARD_OFFSET_TOLERANCE_COUNTS;
  c.vbus_divider_milli = POUR_BOARD_VBUS_DIVIDER_MILLI;
  c.encoder_cpr = 4096;
  c.encoder_offset = 0;
  c.phase_sum_ma = 4000;
  c.phase_loss_ms = 20;
  c.encoder_check_urad = 3000;
  c.encoder_reversed = 0;
  c.cal_current_ma = 4000;    /* 1.2× the nominal current for 3.1 s: 0.16 N·m of hold at the motor */
  c.cal_l_test_mv = 1000;     /* 0.33 A of ripple a period on the rig's 150 µH */
  c.cal_motion_urad = 174533; /* 10° of output; an electrical turn of this motor is 2.25° through 1:20 */
  return c;
}

static int in_range(uint32_t x, uint32_t lo, uint32_t hi) { return x >= lo && x <= hi; }

const char *pour_drive_config_check(const pour_drive_config_t *c) {
  if (c == NULL) return "config";
  if (!in_range(c->pwm_hz, 16000, 40000)) return "pwm_hz";
  if (!in_range(c->timer_clock_hz, 1000000, 500000000) || c->timer_clock_hz / (2u * c->pwm_hz) > 65535u)
    return "timer_clock_hz";
  if ((uint64_t)c->deadtime_ns * c->pwm_hz * 20u > 1000000000ULL) return "deadtime_ns";
  if (!in_range(c->r_phase_uohm, POUR_MOTOR_R_MIN_UOHM, POUR_MOTOR_R_MAX_UOHM)) return "r_phase_uohm";
  if (!in_range(c->ld_nh, POUR_MOTOR_L_MIN_NH, POUR_MOTOR_L_MAX_NH)) return "ld_nh";
  if (!in_range(c->lq_nh, POUR_MOTOR_L_MIN_NH, POUR_MOTOR_L_MAX_NH)) return "lq_nh";
  if (!in_range(c->kt_unm_per_a, 1, 1000000)) return "kt_unm_per_a";
  if (!in_range(c->pole_pairs, 1, POUR_MOTOR_POLE_PAIRS_MAX)) return "pole_pairs";
  if (!in_range(c->gear_ratio, 1, 1000)) return "gear_ratio";
  if (!in_range(c->gear_efficiency_q15, 16384, 32768)) return "gear_efficiency_q15";
  /* ωc·20 <= 2π·f: the loop's delay (1.5 periods) then costs at most 27° of phase margin */
  if (c->bandwidth_rad_s == 0u ||
      (uint64_t)c->bandwidth_rad_s * POUR_DRIVE_BANDWIDTH_DIVISOR * 1000000u > (uint64_t)TWO_PI_URAD * c->pwm_hz)
    return "bandwidth_rad_s";
  if (!in_range(c->current_limit_ma, 100, 60000)) return "current_limit_ma";
  if (c->overcurrent_ma <= c->current_limit_ma || c->overcurrent_ma >= (uint32_t)I_BASE) return "overcurrent_ma";
  if (c->i_cont_ma == 0u || c->i_cont_ma > c->current_limit_ma) return "i_cont_ma";
  if (!in_range(c->i2t_budget_a2s, 1, 1000000)) return "i2t_budget_a2s";
  if (!in_range(c->vbus_uv_mv, 1000, 60000)) return "vbus_uv_mv";
  if (c->vbus_ov_mv <= c->vbus_uv_mv || c->vbus_ov_mv >= (uint32_t)V_BASE) return "vbus_ov_mv";
  if (c->regen_on_mv <= c->vbus_uv_mv || c->regen_on_mv >= c->vbus_ov_mv) return "regen_on_mv";
  if (c->regen_full_mv <= c->regen_on_mv || c->regen_full_mv > c->vbus_ov_mv) return "regen_full_mv";
  if (c->flux_brake_ma > c->current_limit_ma) return "flux_brake_ma";
  if (c->regen_enabled > 1u) return "regen_enabled";
  if (!in_range(c->shunt_uohm, 100, 1000000)) return "shunt_uohm";
  if (!in_range(c->amp_gain_milli, 100, 1000000)) return "amp_gain_milli";
  if (!in_range(c->adc_vref_mv, 1000, 5000)) return "adc_vref_mv";
  if (c->offset_nominal > 4095u || c->offset_tolerance == 0u || c->offset_tolerance > 2047u)
    return "offset_nominal";
  if (!in_range(c->vbus_divider_milli, 1000, 100000)) return "vbus_divider_milli";
  if (!in_range(c->encoder_cpr, 256, 65536) || (c->encoder_cpr & (c->encoder_cpr - 1u)) != 0u) return "encoder_cpr";
  if (!in_range(c->phase_sum_ma, 100, 60000)) return "phase_sum_ma";
  if (!in_range(c->phase_loss_ms, 1, 1000)) return "phase_loss_ms";
  if (!in_range(c->encoder_check_urad, 1000, 1000000)) return "encoder_check_urad";
  if (c->encoder_reversed > 1u) return "encoder_reversed";
  if (!in_range(c->cal_current_ma, 100, c->current_limit_ma) || c->cal_current_ma > (uint32_t)I_BASE / 2u)
    return "cal_current_ma";
  if (!in_range(c->cal_l_test_mv, 100, 10000)) return "cal_l_test_mv";
  /* an electrical turn of a 32-pole-pair motor at the output .. half a turn */
  if ((uint64_t)c->cal_motion_urad * POUR_MOTOR_POLE_PAIRS_MAX * c->gear_ratio < TWO_PI_URAD ||
      c->cal_motion_urad > TWO_PI_URAD / 2u)
    return "cal_motion_urad";
  return NULL;
}

static int32_t ma_q15(uint32_t ma) { return (int32_t)(((uint64_t)ma * 32768u + I_BASE / 2) / I_BASE); }
static int32_t mv_q15(uint32_t mv) { return (int32_t)(((uint64_t)mv * 32768u + V_BASE / 2) / V_BASE); }

pour_status_t pour_drive_init(pour_drive_t *drv, const pour_drive_config_t *config) {
  if (drv == NULL || pour_drive_config_check(config) != NULL) return POUR_EINVAL;
  const pour_drive_config_t *c = config;
  memset(drv, 0, sizeof *drv);
  drv->config = *c;
  if (pour_current_pi_init(&drv->pi_d, c->bandwidth_rad_s, c->ld_nh, c->r_phase_uohm, c->pwm_hz, I_BASE, V_BASE) !=
          POUR_OK ||
      pour_current_pi_init(&drv->pi_q, c->bandwidth_rad_s, c->lq_nh, c->r_phase_uohm, c->pwm_hz, I_BASE, V_BASE) !=
          POUR_OK)
    return POUR_EINVAL;
  /* phase current per count: (vref/4096) / (shunt·gain), in Q15 of I_BASE, Q16 (32768·65536/4096 = 2^19) */
  const uint64_t i_den = (uint64_t)c->shunt_uohm * c->amp_gain_milli;
  const uint64_t i_gain = ((uint64_t)c->adc_vref_mv * (1000000000u / I_BASE) * (1u << 19) + i_den / 2u) / i_den;
  const pour_current_sense_config_t sense = {(int32_t)i_gain, c->offset_nominal, c->offset_tolerance};
  if (i_gain == 0u || i_gain > (uint64_t)INT32_MAX || pour_current_sense_init(&drv->sense, &sense) != POUR_OK)
    return POUR_EINVAL;
  /* bus voltage per count: vref·divider/4096 [mV], in Q15 of V_BASE, Q16 */
  drv->vbus_gain_q16 = (int32_t)(((uint64_t)c->adc_vref_mv * c->vbus_divider_milli * (1u << 19) / 1000u + V_BASE / 2) / V_BASE);
  /* iq [Q15] per mN·m at the output: 1e-3/(N·η·Kt) A, Kt in µN·m/A: 1e3·(32768/I_BASE)·2^16 / (N·η·Kt·1e-6)
   * with η = eff/32768 */
  const uint64_t t_den = (uint64_t)c->gear_ratio * c->gear_efficiency_q15 * c->kt_unm_per_a;
  const uint64_t t_num = (uint64_t)(1000000000ULL / I_BASE) * 32768u * 32768u * 65536u / 1000u;
  const uint64_t t_gain = (t_num + t_den / 2u) / t_den;
  if (t_gain == 0u || t_gain > (uint64_t)INT32_MAX) return POUR_EINVAL;
  drv->torque_to_iq_q16 = (int32_t)t_gain;
  drv->period = (uint16_t)(c->timer_clock_hz / (2u * c->pwm_hz));
  drv->modulation.deadtime_duty_q15 = (int32_t)((uint64_t)c->deadtime_ns * c->pwm_hz * 32768u / 1000000000u);
  drv->modulation.deadtime_band_q15 = ma_q15(DEADTIME_BAND_MA);
  drv->modulation.duty_max_q15 = DUTY_MAX_Q15;
  drv->limit_q15 = ma_q15(c->current_limit_ma);
  drv->overcurrent_q15 = ma_q15(c->overcurrent_ma);
  drv->phase_sum_q15 = ma_q15(c->phase_sum_ma);
  drv->flux_brake_q15 = ma_q15(c->flux_brake_ma);
  drv->regen_on_q15 = mv_q15(c->regen_on_mv);
  drv->regen_span_q15 = mv_q15(c->regen_full_mv) - drv->regen_on_q15;
  if (drv->regen_span_q15 <= 0) return POUR_EINVAL;
  drv->ov_q15 = mv_q15(c->vbus_ov_mv);
  drv->uv_q15 = mv_q15(c->vbus_uv_mv);
  uint8_t log2_cpr = 0;
  while ((1u << log2_cpr) < c->encoder_cpr) ++log2_cpr;
  drv->elec_shift = (uint8_t)(16u - log2_cpr);
  const int64_t ic = ma_q15(c->i_cont_ma);
  drv->i_cont2_q30 = ic * ic;
  /* A²·s → (A/I_BASE)²·ms in Q30 */
  drv->i2t_budget_q30ms = (int64_t)((uint64_t)c->i2t_budget_a2s * 1000u * (1ULL << 30) /
                                    ((uint64_t)(I_BASE / 1000) * (I_BASE / 1000)));
  drv->phase_loss_limit = c->phase_loss_ms * c->pwm_hz / 1000u;
  drv->state = POUR_DRIVE_CALIBRATING;
  return POUR_OK;
}

void pour_drive_trip(pour_drive_t *drv, uint16_t fault) {
  if (drv->state == POUR_DRIVE_MEASURING) {
    drv->cal_status = POUR_MOTOR_CAL_ABORTED;
    fault |= POUR_DRIVE_FAULT_CALIBRATION;
  }
  drv->faults = (uint16_t)(drv->faults | (fault & POUR_DRIVE_FAULT_ALL));
  drv->state = POUR_DRIVE_FAULTED;
  pour_current_pi_reset(&drv->pi_d);
  pour_current_pi_reset(&drv->pi_q);
  drv->iq_cmd_q15 = 0;
}

/* Back to zero current: the PI loops, the command and the supervision windows start afresh. */
static void restart(pour_drive_t *drv) {
  pour_current_pi_reset(&drv->pi_d);
  pour_current_pi_reset(&drv->pi_q);
  drv->iq_cmd_q15 = 0;
  drv->phase_loss_count = 0;
  drv->motor_counts = drv->output_urad = 0;
}

uint16_t pour_drive_clear_faults(pour_drive_t *drv) {
  if (drv->state != POUR_DRIVE_FAULTED) return drv->faults;
  if (drv->faults & POUR_DRIVE_FAULT_CURRENT_OFFSET) {
    /* Measured again with the gates off (CALIBRATING); the fault stays latched until they are in range. */
    const pour_current_sense_config_t sc = drv->sense.config;
    (void)pour_current_sense_init(&drv->sense, &sc); /* valid: checked at init */
    restart(drv);
    drv->state = POUR_DRIVE_CALIBRATING;
    return drv->faults;
  }
  if (!drv->sense.calibrated) return drv->faults;
  uint16_t keep = (uint16_t)(drv->faults & ~POUR_DRIVE_FAULT_CLEARABLE);
  if (drv->vbus_q15 > drv->ov_q15) keep |= (uint16_t)(drv->faults & POUR_DRIVE_FAULT_OVERVOLTAGE);
  if (drv->vbus_q15 < drv->uv_q15) keep |= (uint16_t)(drv->faults & POUR_DRIVE_FAULT_UNDERVOLTAGE);
  if (drv->heat_q30ms > drv->i2t_budget_q30ms / 2) keep |= (uint16_t)(drv->faults & POUR_DRIVE_FAULT_I2T);
  drv->faults = keep;
  if (keep != 0u) return keep;
  restart(drv);
  drv->state = POUR_DRIVE_RUN;
  return 0u;
}

static int32_t abs_i32(int32_t x) { return x < 0 ? -x : x; }
static int32_t clamp_i32(int32_t x, int32_t lo, int32_t hi) { return x < lo ? lo : (x > hi ? hi : x); }

/* The outputs of a period without current control: bridge off while uncalibrated, else every low side on
 * (the windings shorted: no current into the bus, braking torque), brake engaged. */
static void hold(const pour_drive_t *drv, pour_drive_output_t *out) {
  for (int k = 0; k < 3; ++k) {
    out->compare[k] = 0;
    out->duty[k] = 0;
  }
  out->pwm_enable = drv->sense.calibrated;
  out->brake = 1;
  out->faults = drv->faults;
}

static uint16_t compare_of(int32_t duty_q15, uint16_t period) {
  return (uint16_t)(((uint32_t)duty_q15 * period + (1u << 14)) >> 15);
}

static int32_t vmax_of(q15_t vbus) { return (int32_t)(((int64_t)vbus * VMAX_OF_BUS_Q15) >> 15); }

bool pour_drive_can_calibrate(const pour_drive_t *drv) {
  /* the latched faults a calibration may start from are those its success clears */
  return drv->state == POUR_DRIVE_RUN ||
         (drv->state == POUR_DRIVE_FAULTED && drv->sense.calibrated &&
          (drv->faults & (uint16_t)~POUR_DRIVE_FAULT_CLEARED_BY_CALIBRATION) == 0u);
}

pour_status_t pour_drive_calibrate(pour_drive_t *drv) {
  const pour_drive_config_t *c = &drv->config;
  if (!pour_drive_can_calibrate(drv)) return POUR_EINVAL;
  const pour_motor_cal_config_t mc = {
      c->pwm_hz, I_BASE, V_BASE, c->cal_current_ma, c->cal_l_test_mv, c->encoder_cpr,
      (uint32_t)((uint64_t)c->cal_motion_urad * c->gear_ratio * c->encoder_cpr / TWO_PI_URAD)};
  if (pour_motor_cal_init(&drv->cal, &mc, drv->last_encoder) != POUR_OK) return POUR_EINVAL;
  pour_current_pi_reset(&drv->pi_d);
  pour_current_pi_reset(&drv->pi_q);
  drv->iq_cmd_q15 = 0;
  drv->cal_status = POUR_MOTOR_CAL_RUNNING;
  drv->state = POUR_DRIVE_MEASURING;
  return POUR_OK;
}

void pour_drive_calibrate_abort(pour_drive_t *drv) {
  if (drv->state == POUR_DRIVE_MEASURING) pour_drive_trip(drv, POUR_DRIVE_FAULT_CALIBRATION);
}

pour_motor_cal_status_t pour_drive_calibration(const pour_drive_t *drv, pour_motor_cal_result_t *result) {
  if (drv->cal_status == POUR_MOTOR_CAL_OK && result != NULL) *result = drv->cal_result;
  return drv->cal_status;
}

/* The motor's numbers a self-calibration measures, as the configuration holds them. */
typedef struct {
  uint32_t r_phase_uohm, ld_nh, lq_nh, pole_pairs, encoder_reversed;
  uint16_t encoder_offset;
} motor_numbers_t;

/* Puts *m into the configuration; returns the numbers it held. */
static motor_numbers_t exchange_motor_numbers(pour_drive_config_t *c, const motor_numbers_t *m) {
  const motor_numbers_t was = {c->r_phase_uohm, c->ld_nh, c->lq_nh, c->pole_pairs, c->encoder_reversed,
                               c->encoder_offset};
  c->r_phase_uohm = m->r_phase_uohm;
  c->ld_nh = m->ld_nh;
  c->lq_nh = m->lq_nh;
  c->pole_pairs = m->pole_pairs;
  c->encoder_reversed = m->encoder_reversed;
  c->encoder_offset = m->encoder_offset;
  return was;
}

/* A period of the self-calibration: its voltage vector through the same modulation as the current loop's;
 * at its end, the results into the configuration and RUN, or the reason latched. */
static void measure(pour_drive_t *drv, uint16_t encoder, const q15_t i[3], q15_t alpha, q15_t beta,
                    pour_drive_output_t *out) {
  q15_t va, vb;
  const pour_motor_cal_status_t st = pour_motor_cal_step(&drv->cal, alpha, beta, encoder, vmax_of(out->vbus), &va, &vb);
  if (st == POUR_MOTOR_CAL_RUNNING) {
    pour_foc_modulate_q15(va, vb, out->vbus, i, &drv->modulation, out->duty);
    for (int k = 0; k < 3; ++k) out->compare[k] = compare_of(out->duty[k], drv->period);
    out->pwm_enable = 1;
    out->brake = 0;
    out->faults = drv->faults;
    return;
  }
  if (st == POUR_MOTOR_CAL_OK) {
    const pour_motor_cal_result_t r = drv->cal.result;
    /* The results go into the configuration itself, the numbers they replace kept to be put back if it
     * fails its check (a copy of the whole configuration would be 140 B on this interrupt's stack). */
    const motor_numbers_t measured = {r.r_phase_uohm, r.l_phase_nh, r.l_phase_nh, r.pole_pairs,
                                      r.encoder_direction < 0 ? 1u : 0u, r.electrical_offset};
    const motor_numbers_t was = exchange_motor_numbers(&drv->config, &measured);
    const pour_drive_config_t *c = &drv->config;
    /* Only the motor's numbers change: the current loop's gains from them, the rest (the offsets, the bases,
     * the limits) stays, so this period costs two gain computations rather than a whole init. */
    pour_current_pi_t pi_d, pi_q;
    if (pour_drive_config_check(c) == NULL &&
        pour_current_pi_init(&pi_d, c->bandwidth_rad_s, c->ld_nh, c->r_phase_uohm, c->pwm_hz, I_BASE, V_BASE) == POUR_OK &&
        pour_current_pi_init(&pi_q, c->bandwidth_rad_s, c->lq_nh, c->r_phase_uohm, c->pwm_hz, I_BASE, V_BASE) == POUR_OK) {
      drv->pi_d = pi_d;
      drv->pi_q = pi_q;
      drv->cal_status = POUR_MOTOR_CAL_OK;
      drv->cal_result = r;
      drv->faults = 0; /* what it started from (POUR_DRIVE_FAULT_CLEARED_BY_CALIBRATION): a trip would end it */
      restart(drv);
      drv->last_encoder = encoder;
      drv->state = POUR_DRIVE_RUN; /* at zero current from the next period */
      hold(drv, out);
      return;
    }
    (void)exchange_motor_numbers(&drv->config, &was);
  }
  pour_drive_trip(drv, POUR_DRIVE_FAULT_CALIBRATION);
  /* R and L in range whose current-loop gains (Kp = ωc·L) do not fit Q16.16: L is what is implausible */
  drv->cal_status = st == POUR_MOTOR_CAL_OK ? POUR_MOTOR_CAL_INDUCTANCE : st;
  hold(drv, out);
}

void pour_drive_isr(pour_drive_t *drv, const pour_drive_sample_t *in, pour_drive_output_t *out) {
  const pour_drive_config_t *c = &drv->config;
  out->id = out->iq = out->id_ref = out->iq_ref = 0;
  out->limits = 0;
  out->vbus = pour_sat_q15((int32_t)(((int64_t)in->adc_vbus * drv->vbus_gain_q16 + (1 << 15)) >> 16)); /* < 2^47 >> 16 */
  if (drv->state == POUR_DRIVE_CALIBRATING) {
    drv->vbus_q15 = out->vbus; /* a clear right after the offsets judges the bus of now, not of before them */
    const int r = pour_current_sense_calibrate(&drv->sense, in->adc_phase);
    if (r < 0) {
      pour_drive_trip(drv, POUR_DRIVE_FAULT_CURRENT_OFFSET);
    } else if (r > 0) {
      drv->faults = (uint16_t)(drv->faults & ~POUR_DRIVE_FAULT_CURRENT_OFFSET); /* a clear's re-measure passed */
      drv->state = drv->faults != 0u ? POUR_DRIVE_FAULTED : POUR_DRIVE_RUN;
      drv->last_encoder = in->encoder;
    }
    hold(drv, out);
    out->pwm_enable = 0;
    return;
  }
  q15_t i[3];
  pour_current_sense_convert(&drv->sense, in->adc_phase, i);
  if (drv->state == POUR_DRIVE_RUN || drv->state == POUR_DRIVE_MEASURING) {
    uint16_t f = 0;
    for (int k = 0; k < 3; ++k)
      if (abs_i32(i[k]) > drv->overcurrent_q15) f |= POUR_DRIVE_FAULT_OVERCURRENT;
    if (abs_i32((int32_t)i[0] + i[1] + i[2]) > drv->phase_sum_q15) f |= POUR_DRIVE_FAULT_PHASE;
    if (out->vbus > drv->ov_q15) f |= POUR_DRIVE_FAULT_OVERVOLTAGE;
    if (out->vbus < drv->uv_q15) f |= POUR_DRIVE_FAULT_UNDERVOLTAGE;
    if (f) pour_drive_trip(drv, f);
  }
  /* encoder motion, wrapped on its counter's modulus */
  const int32_t cpr = (int32_t)c->encoder_cpr;
  int32_t step = ((int32_t)in->encoder - (int32_t)drv->last_encoder) & (cpr - 1);
  if (step >= cpr / 2) step -= cpr;
  if (c->encoder_reversed) step = -step;
  drv->motor_counts += step;
  drv->last_encoder = in->encoder;
  const uint32_t poles = (uint32_t)in->encoder * c->pole_pairs;
  const uint16_t angle =
      (uint16_t)((((c->encoder_reversed ? 0u - poles : poles)) << drv->elec_shift) + c->encoder_offset);
  q15_t s, co, alpha, beta, id, iq;
  pour_foc_sincos_q15(angle, &s, &co);
  pour_foc_clarke_q15(i[0], i[1], i[2], &alpha, &beta);
  if (drv->state == POUR_DRIVE_MEASURING) {
    drv->i2_sum_q30 += (int64_t)alpha * alpha + (int64_t)beta * beta; /* |i|², as id² + iq² (Park rotates) */
    drv->i2_n++;
    measure(drv, in->encoder, i, alpha, beta, out);
    return;
  }
  pour_foc_park_q15(alpha, beta, s, co, &id, &iq);
  out->id = id;
  out->iq = iq;
  drv->i2_sum_q30 += (int64_t)id * id + (int64_t)iq * iq;
  drv->i2_n++;
  if (drv->state != POUR_DRIVE_RUN) {
    drv->vbus_q15 = out->vbus; /* for a clear; kept off the running path, the interrupt's longest */
    hold(drv, out);
    return;
  }
  uint16_t limits = 0;
  /* flux braking: d current rising from 0 at regen_on to flux_brake at regen_full */
  int32_t id_ref = 0;
  if (c->regen_enabled && out->vbus > drv->regen_on_q15) {
    const int32_t over = clamp_i32(out->vbus - drv->regen_on_q15, 0, drv->regen_span_q15);
    id_ref = drv->flux_brake_q15 * over / drv->regen_span_q15; /* < 2^15 · 2^15: int32 */
    limits |= POUR_DRIVE_LIMIT_FLUX_BRAKE;
  }
  const int32_t iq_max = id_ref == 0 ? drv->limit_q15
                                      : (int32_t)pour_foc_isqrt_u32((uint32_t)(drv->limit_q15 * drv->limit_q15 -
                                                                               id_ref * id_ref));
  const int32_t iq_ref = clamp_i32(drv->iq_cmd_q15, -iq_max, iq_max);
  if (iq_ref != drv->iq_cmd_q15) limits |= POUR_DRIVE_LIMIT_CURRENT;
  /* the voltage vector within vmax, d first (flux braking keeps its current), q takes what is left */
  const int32_t vmax = vmax_of(out->vbus);
  const int32_t ed = id_ref - id, eq = iq_ref - iq;
  const q15_t vd = pour_current_pi_step(&drv->pi_d, ed, vmax);
  const int32_t vq_max = (int32_t)pour_foc_isqrt_u32((uint32_t)(vmax * vmax - (int32_t)vd * vd));
  const q15_t vq = pour_current_pi_step(&drv->pi_q, eq, vq_max);
  const int saturated = abs_i32(vq) >= vq_max || abs_i32(vd) >= vmax;
  if (saturated) limits |= POUR_DRIVE_LIMIT_VOLTAGE;
  /* lost current control: a phase open (or the motor far beyond its base speed) */
  const int32_t ref = abs_i32(iq_ref) > abs_i32(id_ref) ? abs_i32(iq_ref) : abs_i32(id_ref);
  if (saturated && ref > drv->limit_q15 / 10 && abs_i32(ed) + abs_i32(eq) > ref / 4) {
    if (++drv->phase_loss_count >= drv->phase_loss_limit) pour_drive_trip(drv, POUR_DRIVE_FAULT_PHASE);
  } else {
    drv->phase_loss_count = 0;
  }
  if (drv->state != POUR_DRIVE_RUN) {
    hold(drv, out);
    return;
  }
  if (drv->heat_q30ms > drv->i2t_budget_q30ms / 2) limits |= POUR_DRIVE_LIMIT_I2T;
  pour_foc_inv_park_q15(vd, vq, s, co, &alpha, &beta);
  pour_foc_modulate_q15(alpha, beta, out->vbus, i, &drv->modulation, out->duty);
  for (int k = 0; k < 3; ++k) out->compare[k] = compare_of(out->duty[k], drv->period);
  out->pwm_enable = 1;
  out->brake = 0;
  out->id_ref = (q15_t)id_ref;
  out->iq_ref = (q15_t)iq_ref;
  out->limits = limits;
  out->faults = drv->faults;
}

/* I²t: the mean i² of this millisecond above the continuous current's, accrued; cooling below it. Returns
 * whether periods ran this millisecond. */
static int accrue_i2t(pour_drive_t *drv) {
  if (drv->i2_n == 0u) return 0;
  drv->heat_q30ms += drv->i2_sum_q30 / drv->i2_n - drv->i_cont2_q30;
  if (drv->heat_q30ms < 0) drv->heat_q30ms = 0;
  drv->i2_sum_q30 = 0;
  drv->i2_n = 0;
  return 1;
}

void pour_drive_tick(pour_drive_t *drv, int32_t torque_mnm, int32_t output_delta_urad) {
  const pour_drive_config_t *c = &drv->config;
  if (drv->state == POUR_DRIVE_FAULTED) {
    accrue_i2t(drv); /* the motor cools while held: a clear waits for it */
    return;
  }
  if (drv->state == POUR_DRIVE_MEASURING) {
    /* the sequence's test current heats the motor as a torque would: a hot start ends in the I²t fault */
    if (accrue_i2t(drv) && drv->heat_q30ms > drv->i2t_budget_q30ms) pour_drive_trip(drv, POUR_DRIVE_FAULT_I2T);
    return;
  }
  if (drv->state != POUR_DRIVE_RUN) {
    drv->i2_sum_q30 = 0;
    drv->i2_n = 0;
    return;
  }
  /* Braking (the load drives the motor through the gearbox) the gearbox's loss helps: the motor then needs
   * η² less current than motoring for the same torque at the output. */
  int64_t gain = drv->torque_to_iq_q16;
  if ((torque_mnm > 0 && output_delta_urad < 0) || (torque_mnm < 0 && output_delta_urad > 0)) {
    const int64_t eff = c->gear_efficiency_q15;
    gain = (gain * eff * eff + (1LL << 29)) >> 30;
  }
  const int64_t iq = ((int64_t)torque_mnm * gain + (1 << 15)) >> 16;
  drv->iq_cmd_q15 = (int32_t)(iq > drv->limit_q15 ? drv->limit_q15 : (iq < -drv->limit_q15 ? -drv->limit_q15 : iq));
  if (accrue_i2t(drv) && drv->heat_q30ms > drv->i2t_budget_q30ms) {
    pour_drive_trip(drv, POUR_DRIVE_FAULT_I2T);
    return;
  }
  /* the motor encoder against the output's motion: counts expected = Δθ·N·cpr/2π */
  drv->output_urad += output_delta_urad;
  if (abs_i32(drv->output_urad) >= (int32_t)c->encoder_check_urad) {
    const int64_t expected = (int64_t)drv->output_urad * c->gear_ratio * c->encoder_cpr / TWO_PI_URAD;
    /* Only a clear reversal trips: at least half the expected counts the other way. A motor that moved less
     * (the gearbox's backlash taken up, the output falling through it) is no evidence either way. */
    const int64_t seen = drv->motor_counts;
    if ((expected > 0 && 2 * seen <= -expected) || (expected < 0 && 2 * seen >= -expected))
      pour_drive_trip(drv, POUR_DRIVE_FAULT_ENCODER_DIRECTION);
    drv->output_urad = 0;
    drv->motor_counts = 0;
  }
}
