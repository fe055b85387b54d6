/* SPDX-License-Identifier: MIT */
/* Each board fault injected through the HAL into the closed loop the board runs, and the bucket ends held.
 * The loop is the production code: the core (pour_control, its decisions a PD from outside, as host_sim's
 * baselines give them), board_drive (the current loop's interrupt 20 times a tick over pour_drive_isr, the
 * protection, the drive's faults into the core, the torque handed to the loop) and port_tick's outputs. The
 * HAL (hal_drive, hal_brake, hal_power) is implemented here by a plant: the bucket of 10 L on its axis
 * (inertia, gravity torque m·g·r·sin θ), a motor through a 1:20 gearbox whose currents follow the loop's
 * references (tests/board/ideal_drive.h) while the gates follow the loop and the power stage is on, a
 * damping torque b·ω while the phases are shorted (b = (Kt·N)²/R of the motor library's EC 45 flat),
 * nothing while the gates are off or the coupling has slipped, and a spring-applied brake on the output
 * shaft that holds 20 N·m once engaged for 20 ms. The core's sensors are the plant's: the output encoder
 * (17 bits) and the two scales. Injected at 300 ms into a tilt at 0.5 rad/s: the comparators' break, a
 * sagging and a pumped-up bus, a hot power stage, a slipping coupling; and a missing calibration at boot; a
 * ClearErrors in the middle of an active stop, which releases nothing; a ClearErrors after a break whose cause
 * is gone (the core back to RUN, the brake released by the core alone, the torque within the slew limit)
 * and one while the comparator still trips (everything kept).
 * Checked: the fault named in the drive's word and the core in FAULT with POUR_FAULT_DRIVE, an active stop
 * (power on) where the drive is still trusted and the phases shorted where it is not, the brake engaged
 * and holding at the end, within 10° of where the fault began, and no tick between the fault and the
 * brake's hold with the bucket free (gates off, power off or nothing holding it: coasting). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "board_drive.h"
#include "brake_power_lines.h"
#include "hal_drive.h"
#include "ideal_drive.h"
#include "pour/board_facts.h"
#include "pour/control.h"
#include "unity.h"

#define DT 0.001
#define MASS 10.0
#define ARM 0.12
#define INERTIA 0.35
#define G 9.81
#define B_SHORT (0.0404 * 20.0 * 0.0404 * 20.0 / 0.573) /* (Kt·N)²/R_terminal [N·m·s] */
#define BRAKE_DELAY_S 0.020
#define BRAKE_HOLD_NM 20.0
#define TAU_MAX_NM 20.0
#define PERIODS 20
#define WARMUP_MS 20 /* the loop's offset calibration (12.8 ms) before the first sample reaches the core */
#define PI 3.14159265358979

typedef enum { GATES_OFF, GATES_ON, SHORTED } gates_t;

static struct {
  double theta, omega, slip; /* slip: motor-side angle minus output angle, after the coupling slips [rad] */
  bool brake_held, slipping, comparator_trip, breaked;
  double brake_since;
  gates_t gates;
  double vbus_v, temp_c;
  unsigned coasting_ticks;
} plant;

static pour_control_t ctl;
static pour_drive_config_t drive_config;

/* --- the HAL, as the plant answers it ------------------------------------------------------------- */
pour_status_t pour_hal_drive_init(void) { return POUR_OK; }
uint16_t pour_hal_drive_period(void) { return 4250u; }
void pour_hal_drive_set_compares(const uint16_t compare[3]) { (void)compare; }
void pour_hal_drive_enable(bool on) { plant.gates = on ? GATES_ON : GATES_OFF; }
void pour_hal_drive_short_low_sides(void) { plant.gates = SHORTED; }
pour_status_t pour_hal_drive_arm_overcurrent(const uint16_t offset_counts[3]) {
  (void)offset_counts;
  return POUR_OK;
}
bool pour_hal_drive_overcurrent_tripped(void) { return plant.breaked; }
void pour_hal_drive_clear_overcurrent(void) { plant.breaked = plant.comparator_trip; }
void pour_hal_drive_mask(bool masked) { (void)masked; }

static uint16_t motor_count(void) {
  const double motor_rad = (plant.theta + plant.slip) * 20.0;
  return (uint16_t)((int64_t)floor(motor_rad / (2.0 * PI) * drive_config.encoder_cpr) & 0xFFFF); /* TIM4: 16 bits */
}

static gates_t gates(void) { return plant.breaked ? SHORTED : (power_line ? plant.gates : GATES_OFF); }

bool pour_hal_drive_sample(pour_hal_drive_sample_t *s) {
  const pour_drive_output_t *o = pour_board_drive_output();
  const bool on = gates() == GATES_ON;
  pour_ideal_phase_counts(pour_board_drive_state(), on ? o->id_ref : 0, on ? o->iq_ref : 0, motor_count(),
                          POUR_BOARD_OFFSET_NOMINAL_COUNTS, s->phase); /* the board's chain, not the firmware's idea */
  s->vbus = pour_ideal_adc_counts(&drive_config, (uint32_t)lround(plant.vbus_v * 1e6 / POUR_BOARD_VBUS_DIVIDER_MILLI));
  s->ntc = pour_ideal_adc_counts(&drive_config, (uint32_t)lround(POUR_BOARD_NTC_V0_MV + (plant.temp_c - 25.0) *
                                                                                  POUR_BOARD_NTC_DV_DT_UV_PER_C * 1e-3));
  s->encoder = motor_count();
  return true;
}

/* --- the loop ------------------------------------------------------------------------------------ */
static void plant_step(double t) {
  if (plant.comparator_trip) {
    plant.breaked = true; /* TIM1's break: the hardware, no software in the path */
  }
  double motor = 0.0;
  if (!plant.slipping) {
    const q15_t iq = pour_board_drive_output()->iq_ref;
    const bool motoring = (iq >= 0) == (plant.omega >= 0.0);
    const double iq_nm = pour_ideal_torque_mnm(&drive_config, iq, motoring) * 1e-3;
    motor = gates() == GATES_ON ? iq_nm : (gates() == SHORTED ? -B_SHORT * plant.omega : 0.0);
  }
  if (brake_line && plant.brake_since < 0.0) {
    plant.brake_since = t;
  }
  if (!brake_line) {
    plant.brake_since = -1.0;
    plant.brake_held = false;
  }
  const double gravity = -MASS * G * ARM * sin(plant.theta);
  const double net = motor + gravity;
  if (plant.brake_since >= 0.0 && t - plant.brake_since >= BRAKE_DELAY_S && fabs(net) < BRAKE_HOLD_NM) {
    plant.brake_held = true;
  }
  if (plant.brake_held) {
    plant.omega = 0.0;
    return;
  }
  if (gates() == GATES_OFF && !plant.slipping) {
    plant.coasting_ticks++;
  }
  plant.omega += net / INERTIA * DT;
  plant.theta += plant.omega * DT;
  if (plant.slipping) {
    plant.slip += 2.0 * DT; /* the motor side runs on at 2 rad/s past the slipping coupling */
  }
}

/* The core's sample of the plant: the 17-bit output encoder (0 = upright), 10 kg in the rotating bucket. */
static pour_sensors_t sample_of(uint32_t seq) {
  const int64_t c = (int64_t)llround(plant.theta / (2.0 * PI) * 131072.0);
  const pour_sensors_t s = {seq, (uint32_t)((c % 131072 + 131072) % 131072), 10000, 0};
  return s;
}

typedef enum { F_BREAK, F_UNDERVOLTAGE, F_OVERVOLTAGE, F_OVERTEMP, F_SLIP, F_CALIBRATION, F_SAG_CLEARED, F_SELF_CAL, F_BREAK_CLEARED,
               F_BREAK_PERSISTS } fault_t;

/* F_BREAK_CLEARED, F_BREAK_PERSISTS: the comparators' break for 5 ms, or for good, then a ClearErrors at
 * CLEAR_MS with the bucket held; from then on the decisions tilt it on at 0.5 rad/s from where it was
 * held. What the ticks after the clear did. */
#define CLEAR_MS 900
static struct {
  double theta;
  int brake_not_core_ticks; /* the brake other than the core commands it, from the tick after the clear */
  int released_ticks;
  int32_t torque_step_max; /* the largest change of the core's torque between two ticks in RUN [Q15] */
} after_clear;

/* F_SELF_CAL: an uncalibrated board whose calibration flow (the hook board_loop installs on the board) starts
 * the drive's self-calibration at SELF_CAL_MS; what the tick did while it ran. */
#define SELF_CAL_MS 50
static struct {
  int ms;
  pour_status_t started;
  int measuring_ticks, power_off_ticks, released_ticks, brake_not_drives_ticks;
} self_cal;

static bool self_cal_flow(pour_drive_t *drv, uint8_t mode) {
  (void)mode;
  if (self_cal.ms == SELF_CAL_MS) {
    self_cal.started = pour_drive_calibrate(drv);
  }
  return drv->state == POUR_DRIVE_MEASURING;
}

typedef struct {
  double theta_fault, theta_end, theta_max_dev;
  int detected_ms, held_ms;
  uint16_t drive_faults, core_faults;
  uint8_t mode;
  bool held, brake;
  bool trusted_at_detection; /* the drive still followed a torque when the core learnt of the fault */
  bool power_at_detection, shorted_at_detection, brake_at_detection;
} result_t;

/* Where the decisions after the clear take the bucket: on at 0.5 rad/s. */
static double resumed_theta(double t) { return after_clear.theta + 0.5 * (t - CLEAR_MS * DT); }

static result_t pour_with(fault_t fault) {
  memset(&plant, 0, sizeof plant);
  plant.brake_since = -1.0;
  brake_line = true;
  power_line = false;
  plant.brake_held = true; /* spring-applied: engaged from power-up */
  const bool clearing = fault == F_BREAK_CLEARED || fault == F_BREAK_PERSISTS;
  /* calibrated where gravity has no torque; cleared where the envelope's torque from rest still lifts it */
  const double start = fault == F_SELF_CAL ? 0.0 : (clearing ? 15.0 : 40.0) * PI / 180.0;
  plant.theta = start;
  plant.vbus_v = 24.0;
  plant.temp_c = 40.0;
  drive_config = pour_drive_default_config();
  const pour_control_config_t cc = pour_control_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &cc, 1u));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_board_drive_init(&drive_config, (int32_t)(TAU_MAX_NM * 1000), fault != F_CALIBRATION && fault != F_SELF_CAL));
  memset(&self_cal, 0, sizeof self_cal);
  memset(&after_clear, 0, sizeof after_clear);
  q15_t last_torque = 0;
  uint8_t last_mode = POUR_MODE_IDLE;
  self_cal.started = POUR_EINVAL;
  pour_board_drive_set_calibration(fault == F_SELF_CAL ? self_cal_flow : NULL);
  const int fault_ms = fault == F_CALIBRATION || fault == F_SELF_CAL ? 0 : 300;
  result_t r = {0};
  r.detected_ms = -1;
  for (int ms = 0; ms < 1500; ++ms) {
    const double t = ms * DT;
    if (ms == fault_ms) {
      r.theta_fault = plant.theta;
    }
    if (ms >= fault_ms) {
      switch (fault) {
      case F_BREAK:
      case F_BREAK_CLEARED: plant.comparator_trip = ms < fault_ms + 5; break; /* a 5 ms current spike */
      case F_BREAK_PERSISTS: plant.comparator_trip = true; break;
      case F_UNDERVOLTAGE: plant.vbus_v = fmax(0.0, 24.0 - 0.5 * (ms - fault_ms)); break; /* sags at 0.5 V/ms */
      case F_SAG_CLEARED: plant.vbus_v = r.detected_ms < 0 ? 24.0 - 0.5 * (ms - fault_ms) : 24.0; break;
      case F_OVERVOLTAGE: plant.vbus_v = 24.0 + 0.5 * (ms - fault_ms); break;
      case F_OVERTEMP: plant.temp_c = 40.0 + 2.0 * (ms - fault_ms); break;
      case F_SLIP: plant.slipping = true; break;
      case F_CALIBRATION: break;
      case F_SELF_CAL: break;
      }
    }
    for (int k = 0; k < PERIODS; ++k) {
      pour_board_drive_isr(); /* the ADC's end of sequence, every PWM period */
    }
    pour_control_input_t in;
    memset(&in, 0, sizeof in);
    in.sensors_fresh = ms >= WARMUP_MS;
    in.sensors = sample_of((uint32_t)ms);
    /* A ClearErrors 3 ms into the active stop, the sag already over: the core refuses it, and so must the
     * protection (else the brake would be released under a stop that returns the bucket upright). */
    in.clear_faults = fault == F_SAG_CLEARED && r.detected_ms >= 0 && ms == fault_ms + r.detected_ms + 3;
    if (clearing && ms == CLEAR_MS) {
      in.clear_faults = true;
      after_clear.theta = plant.theta;
    }
    /* The decisions: tilt at 0.5 rad/s with gravity feed-forward (the core's own stop takes over in FAULT). */
    const bool resumed = clearing && ms >= CLEAR_MS;
    const double ref = resumed ? resumed_theta(t) : start + 0.5 * (t - WARMUP_MS * DT);
    const double ff = MASS * G * ARM * sin(plant.theta);
    const double nm = ff + 200.0 * (ref - plant.theta) + 30.0 * (0.5 - plant.omega);
    pour_control_request(&ctl, 0u, (q15_t)lround(fmax(-1.0, fmin(1.0, nm / TAU_MAX_NM)) * 32767.0));
    pour_control_output_t out;
    self_cal.ms = ms;
    pour_board_drive_tick(&ctl, &in, &out);
    if (clearing && ms > CLEAR_MS && out.mode == POUR_MODE_RUN && last_mode == POUR_MODE_RUN) {
      const int32_t step = out.torque > last_torque ? out.torque - last_torque : last_torque - out.torque;
      after_clear.torque_step_max = step > after_clear.torque_step_max ? step : after_clear.torque_step_max;
    }
    if (clearing && ms > CLEAR_MS) {
      after_clear.brake_not_core_ticks += brake_line == out.brake ? 0 : 1;
      after_clear.released_ticks += brake_line ? 0 : 1;
    }
    last_torque = out.torque;
    last_mode = out.mode;
    if (pour_board_drive_state()->state == POUR_DRIVE_MEASURING) {
      self_cal.measuring_ticks++;
      self_cal.power_off_ticks += power_line ? 0 : 1;
      self_cal.released_ticks += brake_line ? 0 : 1;
      self_cal.brake_not_drives_ticks += brake_line == (pour_board_drive_output()->brake != 0u) ? 0 : 1;
    }
    if (in.drive_faults != 0u && r.detected_ms < 0) {
      r.detected_ms = ms - fault_ms;
      r.trusted_at_detection = in.drive_trusted;
      r.power_at_detection = power_line;
      r.brake_at_detection = brake_line;
      r.shorted_at_detection = pour_board_drive_state()->state == POUR_DRIVE_FAULTED;
    }
    if (ms < fault_ms) {
      TEST_ASSERT_EQUAL_HEX16(0u, out.faults); /* nothing before the injection */
    }
    r.drive_faults = in.drive_faults;
    r.core_faults = out.faults;
    r.mode = out.mode;
    plant_step(t);
    if (ms >= fault_ms && fabs(plant.theta - r.theta_fault) > r.theta_max_dev) {
      r.theta_max_dev = fabs(plant.theta - r.theta_fault);
    }
    if (plant.brake_held && r.held_ms == 0 && ms >= fault_ms) {
      r.held_ms = ms - fault_ms + 1;
    }
  }
  r.theta_end = plant.theta;
  r.held = plant.brake_held;
  r.brake = brake_line;
  return r;
}

static void assert_held(const result_t *r, uint16_t fault_bit, int max_detect_ms) {
  printf("fault 0x%04x: detected after %d ms (drive trusted %d: power %d, phases shorted %d, brake %d), brake "
         "holding %d ms after the fault began, moved at most %.2f deg, ended %.2f deg from where it began; core "
         "faults 0x%04x, drive faults 0x%04x\n",
         (unsigned)fault_bit, r->detected_ms, (int)r->trusted_at_detection, (int)r->power_at_detection,
         (int)r->shorted_at_detection, (int)r->brake_at_detection, r->held_ms, r->theta_max_dev * 180.0 / PI,
         fabs(r->theta_end - r->theta_fault) * 180.0 / PI, (unsigned)r->core_faults, (unsigned)r->drive_faults);
  TEST_ASSERT_BITS_HIGH(fault_bit, r->drive_faults);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_DRIVE, r->core_faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, r->mode);
  TEST_ASSERT_TRUE(r->detected_ms >= 0 && r->detected_ms <= max_detect_ms);
  TEST_ASSERT_TRUE(r->brake_at_detection); /* engaged at once, whichever way the bucket is held meanwhile */
  TEST_ASSERT_TRUE(r->brake);
  TEST_ASSERT_TRUE(r->held);
  TEST_ASSERT_DOUBLE_WITHIN(10.0 * PI / 180.0, r->theta_fault, r->theta_end);
  TEST_ASSERT_EQUAL_UINT(0u, plant.coasting_ticks);
}

/* The drive still trusted: the core's active stop drives the motor (power on, the loop running). */
static void assert_active_stop(const result_t *r) {
  TEST_ASSERT_TRUE(r->trusted_at_detection);
  TEST_ASSERT_TRUE(r->power_at_detection);
  TEST_ASSERT_FALSE(r->shorted_at_detection);
}

/* Not trusted: the loop shorts the phases (the power stage on for it) until the brake holds. */
static void assert_shorted(const result_t *r) {
  TEST_ASSERT_FALSE(r->trusted_at_detection);
  TEST_ASSERT_TRUE(r->power_at_detection);
  TEST_ASSERT_TRUE(r->shorted_at_detection);
}

void setUp(void) {}
void tearDown(void) {}

static void test_faults_BreakShortsThePhasesAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_BREAK);
  assert_held(&r, POUR_DRIVE_FAULT_HW_OVERCURRENT, 1);
  assert_shorted(&r);
}

static void test_faults_UndervoltageStopsActivelyAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_UNDERVOLTAGE);
  assert_held(&r, POUR_DRIVE_FAULT_UNDERVOLTAGE, 20);
  assert_active_stop(&r);
}

static void test_faults_AClearDuringTheActiveStopReleasesNothing(void) {
  const result_t r = pour_with(F_SAG_CLEARED);
  assert_held(&r, POUR_DRIVE_FAULT_UNDERVOLTAGE, 20);
  assert_active_stop(&r);
  TEST_ASSERT_EQUAL_UINT32(1u, ctl.refused);
}

static void test_faults_OvervoltageShortsThePhasesAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_OVERVOLTAGE);
  assert_held(&r, POUR_DRIVE_FAULT_OVERVOLTAGE, 20);
  assert_shorted(&r);
}

static void test_faults_OvertemperatureStopsActivelyAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_OVERTEMP);
  assert_held(&r, POUR_DRIVE_FAULT_OVERTEMP, 40);
  assert_active_stop(&r);
}

static void test_faults_SlippingCouplingIsAMismatchAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_SLIP);
  assert_held(&r, POUR_DRIVE_FAULT_ENCODER_MISMATCH, 15);
  assert_shorted(&r);
}

static void test_faults_WithoutCalibrationTheBucketNeverMoves(void) {
  const result_t r = pour_with(F_CALIBRATION);
  assert_held(&r, POUR_DRIVE_FAULT_CALIBRATION, 0);
  TEST_ASSERT_FALSE(r.trusted_at_detection);
  TEST_ASSERT_DOUBLE_WITHIN(0.5 * PI / 180.0, 40.0 * PI / 180.0, r.theta_end);
}

/* The self-calibration on an uncalibrated board runs to its own end: the protection's missing calibration
 * does not re-trip the measuring drive, the power stays on and the brake is the drive's. The motor here
 * draws no current from the sequence's voltages (the ideal drive follows current references only), so the
 * sequence ends on the resistance stage, with the brake engaged and holding (the OK path through this wiring,
 * against host_sim's motor model, is test_board_calibration_run). */
static void test_faults_TheSelfCalibrationOfAnUncalibratedBoardRunsToItsEnd(void) {
  const result_t r = pour_with(F_SELF_CAL);
  printf("self-calibration: %d ms measuring (power off %d, brake released %d, brake not the drive's %d)\n",
         self_cal.measuring_ticks, self_cal.power_off_ticks, self_cal.released_ticks,
         self_cal.brake_not_drives_ticks);
  TEST_ASSERT_EQUAL_INT(POUR_OK, self_cal.started);
  TEST_ASSERT_TRUE(self_cal.measuring_ticks > 10);
  TEST_ASSERT_EQUAL_INT(0, self_cal.power_off_ticks);
  TEST_ASSERT_EQUAL_INT(0, self_cal.brake_not_drives_ticks);
  TEST_ASSERT_TRUE(self_cal.released_ticks > 0);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_RESISTANCE, pour_drive_calibration(pour_board_drive_state(), NULL));
  assert_held(&r, POUR_DRIVE_FAULT_CALIBRATION, 0);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, pour_board_drive_state()->state);
}

/* The cause gone, a ClearErrors re-arms the break and clears the drive: the core back to RUN, the brake
 * released by the core alone, the torque within the slew limit, the bucket following the decisions. */
static void test_faults_AClearAfterTheBreakRunsAgainThroughTheCore(void) {
  const result_t r = pour_with(F_BREAK_CLEARED);
  printf("break cleared: brake released %d ticks, brake not the core's %d ticks, largest torque step %d (Q15), "
         "ended %.2f deg from where the decisions took it\n",
         after_clear.released_ticks, after_clear.brake_not_core_ticks, (int)after_clear.torque_step_max,
         fabs(r.theta_end - resumed_theta(1499 * DT)) * 180.0 / PI);
  TEST_ASSERT_EQUAL_HEX16(0u, r.drive_faults);
  TEST_ASSERT_EQUAL_HEX16(0u, r.core_faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, r.mode);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, pour_board_drive_state()->state);
  TEST_ASSERT_FALSE(plant.breaked);
  TEST_ASSERT_FALSE(r.brake);
  TEST_ASSERT_TRUE(after_clear.released_ticks > 0);
  TEST_ASSERT_EQUAL_INT(0, after_clear.brake_not_core_ticks);
  TEST_ASSERT_TRUE(after_clear.torque_step_max <= pour_control_default_config().safety.slew_per_tick);
  TEST_ASSERT_DOUBLE_WITHIN(3.0 * PI / 180.0, resumed_theta(1499 * DT), r.theta_end);
  TEST_ASSERT_EQUAL_UINT(0u, plant.coasting_ticks);
}

/* The comparator still tripping: the break fires again at the re-arm, and everything stays latched. */
static void test_faults_AClearWhileTheBreakPersistsKeepsItLatched(void) {
  const result_t r = pour_with(F_BREAK_PERSISTS);
  printf("break persisting: brake released %d ticks after the clear, ended %.2f deg from where it was held\n",
         after_clear.released_ticks, fabs(r.theta_end - after_clear.theta) * 180.0 / PI);
  assert_held(&r, POUR_DRIVE_FAULT_HW_OVERCURRENT, 1);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, pour_board_drive_state()->state);
  TEST_ASSERT_TRUE(plant.breaked);
  TEST_ASSERT_EQUAL_INT(0, after_clear.released_ticks);
  TEST_ASSERT_DOUBLE_WITHIN(0.5 * PI / 180.0, after_clear.theta, r.theta_end);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_faults_BreakShortsThePhasesAndTheBrakeHolds);
  RUN_TEST(test_faults_UndervoltageStopsActivelyAndTheBrakeHolds);
  RUN_TEST(test_faults_AClearDuringTheActiveStopReleasesNothing);
  RUN_TEST(test_faults_OvervoltageShortsThePhasesAndTheBrakeHolds);
  RUN_TEST(test_faults_OvertemperatureStopsActivelyAndTheBrakeHolds);
  RUN_TEST(test_faults_SlippingCouplingIsAMismatchAndTheBrakeHolds);
  RUN_TEST(test_faults_WithoutCalibrationTheBucketNeverMoves);
  RUN_TEST(test_faults_TheSelfCalibrationOfAnUncalibratedBoardRunsToItsEnd);
  RUN_TEST(test_faults_AClearAfterTheBreakRunsAgainThroughTheCore);
  RUN_TEST(test_faults_AClearWhileTheBreakPersistsKeepsItLatched);
  return UNITY_END();
}
