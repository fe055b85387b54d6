/* SPDX-License-Identifier: MIT */
/* Each board fault injected through the HAL into a closed loop, and the bucket ends held. The HAL
 * (hal_drive, hal_brake) is implemented here by a plant: the bucket of 10 L on its axis (inertia, gravity
 * torque m·g·r·sin θ), a motor through a 1:20 gearbox that gives the commanded torque while the gates
 * follow the loop and a damping torque b·ω while the phases are shorted (b = (Kt·N)²/R of the motor
 * library's EC 45 flat), nothing while the gates are off or the coupling has slipped, and a spring-applied
 * brake on the output shaft that holds 20 N·m once engaged for 20 ms. The board's supervisor
 * (board_guard.c + protect.c) runs at 1 kHz above a stand-in for the core: a PD that tilts the bucket at
 * 0.5 rad/s, and in an active stop holds it where the fault began. Injected: the comparators' break, a
 * sagging and a pumped-up bus, a hot power stage, a slipping coupling, a missing calibration. Checked: the
 * fault named, the brake engaged and holding at the end, within 10° of where the fault began, and no
 * tick between the fault and the brake's hold with the gates off and no torque (coasting). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "board_guard.h"
#include "hal_brake.h"
#include "hal_drive.h"
#include "unity.h"

#define DT 0.001
#define MASS 10.0
#define ARM 0.12
#define INERTIA 0.35
#define G 9.81
#define KT 0.0369
#define GEAR 20.0
#define R_TERMINAL 0.608
#define B_SHORT (KT * GEAR * KT * GEAR / R_TERMINAL)
#define BRAKE_DELAY_S 0.020
#define BRAKE_HOLD_NM 20.0
#define CPR 4096.0
#define PI 3.14159265358979

typedef enum { GATES_OFF, GATES_ON, SHORTED } gates_t;

static struct {
  double theta, omega, slip; /* slip: motor-side angle minus output angle, after the coupling slips [rad] */
  double torque_cmd;         /* at the output [N·m] */
  bool brake_cmd, brake_held, slipping, comparator_trip, breaked;
  double brake_since;
  gates_t gates;
  double vbus_v, temp_c;
  unsigned coasting_ticks;
} plant;

static pour_guard_t guard;

/* --- the HAL, as the plant answers it ------------------------------------------------------------- */
void pour_hal_brake_init(void) { plant.brake_cmd = true; }
void pour_hal_brake_set(bool engage) { plant.brake_cmd = engage; }
bool pour_hal_brake_engaged(void) { return plant.brake_cmd; }
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

static uint16_t adc_counts(double pin_v) { return (uint16_t)lround(pin_v / 3.3 * 4096.0); }

bool pour_hal_drive_sample(pour_hal_drive_sample_t *s) {
  for (unsigned i = 0; i < 3u; ++i) {
    s->phase[i] = 2048u;
  }
  s->vbus = adc_counts(plant.vbus_v / 19.17);
  s->ntc = adc_counts(1.055 + (plant.temp_c - 25.0) * 0.0227);
  const double motor_rad = (plant.theta + plant.slip) * GEAR;
  s->encoder = (uint16_t)((int64_t)floor(motor_rad / (2.0 * PI) * CPR) & 0xFFFF);
  return true;
}

/* --- the loop ------------------------------------------------------------------------------------ */
static void plant_step(double t) {
  if (plant.comparator_trip) {
    plant.breaked = true; /* TIM1's break: the hardware, no software in the path */
  }
  gates_t gates = plant.breaked ? SHORTED : plant.gates;
  double motor = 0.0;
  if (!plant.slipping) {
    motor = gates == GATES_ON ? plant.torque_cmd : (gates == SHORTED ? -B_SHORT * plant.omega : 0.0);
  }
  if (plant.brake_cmd && plant.brake_since < 0.0) {
    plant.brake_since = t;
  }
  if (!plant.brake_cmd) {
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
  if (gates != GATES_ON && gates != SHORTED && !plant.slipping) {
    plant.coasting_ticks++;
  }
  plant.omega += net / INERTIA * DT;
  plant.theta += plant.omega * DT;
  if (plant.slipping) {
    plant.slip += 2.0 * DT; /* the motor side runs on at 2 rad/s past the slipping coupling */
  }
}

typedef enum { F_BREAK, F_UNDERVOLTAGE, F_OVERVOLTAGE, F_OVERTEMP, F_SLIP, F_CALIBRATION } fault_t;

typedef struct {
  double theta_fault, theta_end, theta_max_dev;
  int detected_ms, held_ms;
  uint16_t faults;
  bool held, brake;
  pour_protect_action_t first_action;
} result_t;

static result_t pour_with(fault_t fault) {
  memset(&plant, 0, sizeof plant);
  plant.brake_since = -1.0;
  plant.theta = 40.0 * PI / 180.0;
  plant.vbus_v = 24.0;
  plant.temp_c = 40.0;
  plant.gates = GATES_ON;
  const pour_guard_config_t gc = pour_guard_default_config();
  const pour_protect_config_t pc = pour_protect_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_guard_init(&guard, &gc, &pc));
  const bool calibrated = fault != F_CALIBRATION;
  const int fault_ms = fault == F_CALIBRATION ? 0 : 300;
  result_t r = {0};
  r.detected_ms = -1;
  double hold = plant.theta;
  for (int ms = 0; ms < 1500; ++ms) {
    const double t = ms * DT;
    if (ms == fault_ms) {
      r.theta_fault = plant.theta;
      hold = plant.theta;
    }
    if (ms >= fault_ms) {
      switch (fault) {
      case F_BREAK: plant.comparator_trip = ms < fault_ms + 5; break; /* a 5 ms current spike */
      case F_UNDERVOLTAGE: plant.vbus_v = 24.0 - 0.5 * (ms - fault_ms); break; /* sags at 0.5 V/ms */
      case F_OVERVOLTAGE: plant.vbus_v = 24.0 + 0.5 * (ms - fault_ms); break;
      case F_OVERTEMP: plant.temp_c = 40.0 + 2.0 * (ms - fault_ms); break;
      case F_SLIP: plant.slipping = true; break;
      case F_CALIBRATION: break;
      }
    }
    const int32_t output_urad = (int32_t)lround(plant.theta * 1e6);
    pour_protect_output_t out;
    pour_guard_tick(&guard, output_urad, true, calibrated, false, &out);
    if (out.faults != 0u && r.detected_ms < 0) {
      r.detected_ms = ms - fault_ms;
      r.first_action = out.action;
    }
    /* The stand-in for the core: tilt at 0.5 rad/s with gravity feed-forward, or hold in an active stop. */
    const double ref = out.action == POUR_PROTECT_RUN ? 40.0 * PI / 180.0 + 0.5 * t : hold;
    const double ff = MASS * G * ARM * sin(plant.theta);
    plant.torque_cmd = (ff + 200.0 * (ref - plant.theta) + 30.0 * ((out.action == POUR_PROTECT_RUN ? 0.5 : 0.0) - plant.omega)) *
                       out.torque_scale / 32767.0;
    if (out.action == POUR_PROTECT_RUN || out.action == POUR_PROTECT_ACTIVE_STOP) {
      if (plant.gates != SHORTED) {
        plant.gates = GATES_ON;
      }
      plant.brake_cmd = out.brake;
    }
    r.faults = out.faults;
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
  r.brake = plant.brake_cmd;
  return r;
}

static void assert_held(const result_t *r, uint16_t fault_bit, int max_detect_ms) {
  printf("fault 0x%04x: detected after %d ms, brake holding %d ms after the fault began, moved at most %.2f deg, "
         "ended %.2f deg from where it began\n",
         (unsigned)fault_bit, r->detected_ms, r->held_ms, r->theta_max_dev * 180.0 / PI,
         fabs(r->theta_end - r->theta_fault) * 180.0 / PI);
  TEST_ASSERT_BITS_HIGH(fault_bit, r->faults);
  TEST_ASSERT_TRUE(r->detected_ms >= 0 && r->detected_ms <= max_detect_ms);
  TEST_ASSERT_TRUE(r->brake);
  TEST_ASSERT_TRUE(r->held);
  TEST_ASSERT_DOUBLE_WITHIN(10.0 * PI / 180.0, r->theta_fault, r->theta_end);
  TEST_ASSERT_EQUAL_UINT(0u, plant.coasting_ticks);
}

void setUp(void) {}
void tearDown(void) {}

static void test_faults_BreakShortsThePhasesAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_BREAK);
  assert_held(&r, POUR_DRIVE_FAULT_HW_OVERCURRENT, 1);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, r.first_action);
}

static void test_faults_UndervoltageStopsActivelyAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_UNDERVOLTAGE);
  assert_held(&r, POUR_DRIVE_FAULT_UNDERVOLTAGE, 20);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_ACTIVE_STOP, r.first_action);
}

static void test_faults_OvervoltageShortsThePhasesAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_OVERVOLTAGE);
  assert_held(&r, POUR_DRIVE_FAULT_OVERVOLTAGE, 20);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, r.first_action);
}

static void test_faults_OvertemperatureStopsActivelyAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_OVERTEMP);
  assert_held(&r, POUR_DRIVE_FAULT_OVERTEMP, 40);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_ACTIVE_STOP, r.first_action);
}

static void test_faults_SlippingCouplingIsAMismatchAndTheBrakeHolds(void) {
  const result_t r = pour_with(F_SLIP);
  assert_held(&r, POUR_DRIVE_FAULT_ENCODER_MISMATCH, 15);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, r.first_action);
}

static void test_faults_WithoutCalibrationTheBucketNeverMoves(void) {
  const result_t r = pour_with(F_CALIBRATION);
  assert_held(&r, POUR_DRIVE_FAULT_CALIBRATION, 0);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_HELD, r.first_action);
  TEST_ASSERT_DOUBLE_WITHIN(0.5 * PI / 180.0, 40.0 * PI / 180.0, r.theta_end);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_faults_BreakShortsThePhasesAndTheBrakeHolds);
  RUN_TEST(test_faults_UndervoltageStopsActivelyAndTheBrakeHolds);
  RUN_TEST(test_faults_OvervoltageShortsThePhasesAndTheBrakeHolds);
  RUN_TEST(test_faults_OvertemperatureStopsActivelyAndTheBrakeHolds);
  RUN_TEST(test_faults_SlippingCouplingIsAMismatchAndTheBrakeHolds);
  RUN_TEST(test_faults_WithoutCalibrationTheBucketNeverMoves);
  return UNITY_END();
}
