/* SPDX-License-Identifier: MIT */
#include "board_drive.h"

#include <stddef.h>
#include <string.h>

#include "board_guard.h"
#include "hal_drive.h"
#include "hal_motor.h"
#include "port_tick.h"

static struct {
  pour_drive_t drive;
  pour_drive_output_t out;         /* the latest period's */
  pour_hal_drive_sample_t latest;  /* the latest period's sample, for the 1 kHz protection */
  uint32_t periods;                /* periods the loop has run */
  uint32_t periods_seen;           /* ... as of the last tick */
  pour_guard_t guard;
  int32_t tau_max_mnm;
  bool calibration_valid;
  bool armed;                      /* the overcurrent cut is armed on the measured offsets */
  uint32_t guard_seq;              /* the core's state the protection saw last: a new one is a fresh output angle */
  int32_t last_theta_urad;
  bool have_theta;                 /* last_theta_urad is a trusted angle */
  uint16_t faults;                 /* the loop's and the protection's, as the core and the bus see them */
  pour_board_calibration_fn calibration; /* the port's calibration flow, or NULL */
  uint16_t settle_ms;              /* after a self-calibration: the brake engaging, the power kept on */
  pour_motor_cal_status_t cal_seen; /* the drive's calibration status at the last tick */
} bd;

pour_status_t pour_board_drive_init(const pour_drive_config_t *config, int32_t tau_max_mnm, bool calibration_valid) {
  memset(&bd.drive, 0, sizeof bd.drive); /* not a copy of a const zero: that would be 512 B of flash */
  bd.periods = bd.periods_seen = 0u;
  bd.armed = false;
  bd.faults = 0u;
  bd.guard_seq = 0u;
  bd.last_theta_urad = 0;
  bd.have_theta = false;
  bd.tau_max_mnm = tau_max_mnm;
  bd.calibration_valid = calibration_valid;
  bd.calibration = NULL;
  bd.settle_ms = 0u;
  bd.cal_seen = POUR_MOTOR_CAL_NONE;
  if (config == NULL || tau_max_mnm <= 0 || pour_drive_init(&bd.drive, config) != POUR_OK) {
    return POUR_EINVAL;
  }
  /* The protection reads the same converters and encoder as the loop: its scales are the drive's. */
  pour_guard_config_t gc = pour_guard_default_config();
  gc.adc_vref_mv = config->adc_vref_mv;
  gc.vbus_divider_milli = config->vbus_divider_milli;
  gc.encoder_cpr = config->encoder_cpr;
  gc.gear_ratio = config->gear_ratio;
  const pour_protect_config_t pc = pour_protect_default_config();
  if (pour_guard_init(&bd.guard, &gc, &pc) != POUR_OK) {
    return POUR_EINVAL;
  }
  return pour_hal_drive_init(); /* last: its interrupt finds the drive ready */
}

void pour_board_drive_set_calibration(pour_board_calibration_fn flow) { bd.calibration = flow; }

void pour_board_drive_calibrated(void) {
  /* The protection starts afresh: the drive's own sequence has just checked the motor encoder against its
   * commutation, so the encoder faults it latched go too, and the output is anchored again. */
  bd.calibration_valid = true;
  const pour_guard_config_t gc = bd.guard.config;
  const pour_protect_config_t pc = bd.guard.protect.config;
  (void)pour_guard_init(&bd.guard, &gc, &pc); /* both checked at init */
}

void pour_board_drive_isr(void) {
  pour_hal_drive_sample_t s;
  if (!pour_hal_drive_sample(&s)) {
    return;
  }
  const pour_drive_sample_t in = {{s.phase[0], s.phase[1], s.phase[2]}, s.vbus, s.encoder};
  const bool offsets = bd.drive.state == POUR_DRIVE_CALIBRATING;
  pour_drive_isr(&bd.drive, &in, &bd.out);
  if (offsets && bd.drive.state == POUR_DRIVE_RUN && !bd.calibration_valid) {
    /* Uncalibrated, the drive never follows a torque: it waits, faulted, for a self-calibration (which needs
     * the offsets just measured), the brake engaged. */
    pour_drive_trip(&bd.drive, POUR_DRIVE_FAULT_CALIBRATION);
  }
  if (bd.drive.state == POUR_DRIVE_FAULTED) {
    pour_hal_drive_short_low_sides(); /* damping, never coasting, until the brake holds */
  } else {
    pour_hal_drive_set_compares(bd.out.compare);
    pour_hal_drive_enable(bd.out.pwm_enable != 0u);
  }
  bd.latest = s;
  bd.periods++;
}

/* Q15 torque, derated by scale (Q15), at tau_max [mN·m], rounded to nearest. */
static int32_t torque_mnm(q15_t torque, q15_t scale, int32_t tau_max_mnm) {
  const int64_t t = (int64_t)torque * scale * tau_max_mnm; /* < 2^15 · 2^15 · 2^31 */
  return (int32_t)((t + (t >= 0 ? (1LL << 29) : -(1LL << 29))) / (1LL << 30));
}

void pour_board_drive_tick(pour_control_t *ctl, pour_control_input_t *in, pour_control_output_t *out) {
  /* A ClearErrors the core would act on reaches the drive first: the protection judges the board's sensors
   * afresh, the loop clears what it may, and the core sees the word as it stands after that. The core
   * refuses the clear while any bit of it stays set, so the drive is never released while still faulted. */
  const bool clear = in->clear_faults && pour_control_clear_acceptable(ctl, in);
  pour_hal_drive_mask(true);
  const bool sampled = bd.periods != bd.periods_seen;
  bd.periods_seen = bd.periods;
  const pour_hal_drive_sample_t s = bd.latest;
  /* With a clear, the protection judges the sensors without the loop's faults a clear may fix; the loop
   * clears only if the protection did, so it never runs while the protection still holds. */
  uint16_t loop_faults = clear ? (uint16_t)(bd.drive.faults & ~POUR_DRIVE_FAULT_CLEARABLE) : bd.drive.faults;
  const bool calibrating = bd.drive.state == POUR_DRIVE_CALIBRATING;
  if (calibrating) {
    /* The offsets measured (again, after a clear of CURRENT_OFFSET): the gates off and the brake engaged
     * below; the cut is armed on the new ones once they pass. */
    loop_faults = (uint16_t)(loop_faults & ~POUR_DRIVE_FAULT_CURRENT_OFFSET);
    bd.armed = false;
  }
  if (!bd.armed && bd.drive.state == POUR_DRIVE_RUN) {
    bd.armed = true; /* the thresholds sit above the offsets the loop has just measured */
    if (pour_hal_drive_arm_overcurrent(bd.drive.sense.offset) != POUR_OK) {
      pour_drive_trip(&bd.drive, POUR_DRIVE_FAULT_CURRENT_OFFSET);
    }
  }
  pour_hal_drive_mask(false);

  const pour_state_t *state = pour_control_state(ctl);
  const bool fresh = ctl->have_trusted && state->seq != bd.guard_seq;
  bd.guard_seq = state->seq;
  pour_protect_output_t p;
  /* A clear the core would refuse (the e-stop, a link fault, the active stop) keeps both latched. */
  pour_guard_tick(&bd.guard, sampled ? &s : NULL, loop_faults, state->theta_urad, fresh, bd.calibration_valid,
                  clear, &p);

  pour_hal_drive_mask(true);
  if (clear && p.faults == 0u) {
    (void)pour_drive_clear_faults(&bd.drive); /* what it keeps stays in the word: the core refuses the clear */
  }
  /* What a calibration clears does not trip (nor short) a drive that measures the motor or has just measured
   * it (the flow stores it this tick); a missing calibration alone not one that measures its offsets with the
   * gates off (the interrupt trips it then). */
  const pour_motor_cal_status_t cal = pour_drive_calibration(&bd.drive, NULL);
  const bool measures =
      cal == POUR_MOTOR_CAL_RUNNING || (cal == POUR_MOTOR_CAL_OK && bd.cal_seen == POUR_MOTOR_CAL_RUNNING);
  bd.cal_seen = cal;
  const uint16_t exempt = measures ? POUR_DRIVE_FAULT_CLEARED_BY_CALIBRATION
                                   : (calibrating ? POUR_DRIVE_FAULT_CALIBRATION : 0u);
  if ((p.action == POUR_PROTECT_SHORT || p.action == POUR_PROTECT_HELD) && (p.faults & (uint16_t)~exempt) != 0u) {
    pour_hal_drive_short_low_sides(); /* now, not at the next period: the loop may not be tripped yet */
    if (bd.drive.state != POUR_DRIVE_FAULTED) {
      pour_drive_trip(&bd.drive, p.faults); /* the loop stops following a torque: its periods short the phases */
    }
  }
  bd.faults = (uint16_t)(bd.drive.faults | p.faults);
  in->drive_faults = bd.faults;
  in->drive_trusted = bd.drive.state == POUR_DRIVE_RUN;
  pour_hal_drive_mask(false);

  pour_control_step(ctl, in, out);
  bool measuring = false;
  if (bd.calibration != NULL) {
    pour_hal_drive_mask(true);
    measuring = bd.calibration(&bd.drive, out->mode);
    pour_hal_drive_mask(false);
  }
  if (measuring) {
    out->brake = bd.out.brake != 0u; /* the sequence releases it while it drives the motor */
    out->power = true;
    bd.settle_ms = bd.guard.protect.config.brake_engage_ms;
  } else if (bd.settle_ms > 0u) {
    /* The sequence has ended with the brake released: until it holds, the power stays on for the shorted
     * phases (a fault) or the held position (a result), never coasting. */
    bd.settle_ms--;
    out->brake = true;
    out->power = true;
  } else if (p.brake) {
    /* A drive fault: the brake engages at once; until it holds, the power stage stays on for the active
     * stop (a trusted drive) or the shorted phases (one that is not). */
    out->brake = true;
    out->power = p.action != POUR_PROTECT_HELD;
  } else if (calibrating) {
    out->brake = true; /* the loop measures its offsets with the gates off: no torque yet to hold the bucket */
    out->power = false;
  }
  pour_port_outputs(out);

  const int32_t delta_urad = bd.have_theta ? (int32_t)((int64_t)state->theta_urad - bd.last_theta_urad) : 0;
  bd.last_theta_urad = state->theta_urad;
  bd.have_theta = ctl->have_trusted;
  const int32_t mnm = torque_mnm(pour_hal_motor_torque(), p.torque_scale, bd.tau_max_mnm);
  pour_hal_drive_mask(true);
  pour_drive_tick(&bd.drive, mnm, delta_urad);
  pour_hal_drive_mask(false);
}

uint16_t pour_board_drive_faults(void) { return bd.faults; }

const pour_drive_t *pour_board_drive_state(void) { return &bd.drive; }

const pour_drive_output_t *pour_board_drive_output(void) { return &bd.out; }

void pour_board_drive_telemetry(pour_can_drive_telemetry_t *t) {
  /* per-unit Q15 of POUR_DRIVE_I_BASE_MA (64 A) -> 2 mA: x 64000 / 32768 / 2 = x 1000 / 1024 */
  t->id_2ma = (int16_t)((int32_t)bd.out.id * 1000 / 1024);
  t->iq_2ma = (int16_t)((int32_t)bd.out.iq * 1000 / 1024);
  t->vbus_mv = (uint16_t)(bd.guard.vbus_mv > 65535u ? 65535u : bd.guard.vbus_mv);
  t->drive_faults = bd.faults;
}
