// SPDX-License-Identifier: MIT
// The full drive (drive = 1) held to the bars of docs/motor.md, each next to the same check with the effect
// switched off, and the injected faults: each latched, the bucket held by the brake, nothing non-finite.
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "controllers.hpp"
#include "motor_checks.hpp"
#include "poursim/poursim.h"

extern "C" {
#include "pour/drive.h"
#include "unity.h"
}

void setUp(void) {}
void tearDown(void) {}

static poursim_config_t full_drive() {
  poursim_config_t c = poursim_default_config();
  c.drive = 1;
  return c;
}

static void test_motor_CurrentStepMeetsTheBars(void) {
  const poursim::CurrentStep s = poursim::measure_current_step(full_drive(), 10.0);
  TEST_ASSERT_TRUE(s.rise_s > 0);
  TEST_ASSERT_TRUE(std::fabs(s.rise_s / s.predicted_rise_s - 1.0) <= 0.20);
  TEST_ASSERT_TRUE(s.overshoot <= 0.10);
  TEST_ASSERT_TRUE(s.ss_error <= 0.01);
}

static void test_motor_CurrentStepCheckSeesAHalvedBandwidth(void) {
  const poursim::CurrentStep design = poursim::measure_current_step(full_drive(), 10.0);
  const poursim::CurrentStep slow = poursim::measure_current_step(full_drive(), 10.0, 1500);
  TEST_ASSERT_TRUE(slow.rise_s / design.predicted_rise_s - 1.0 > 0.20);
}

static void test_motor_ShaftTorqueFollowsTheCommandToBaseSpeed(void) {
  for (const poursim::TorquePoint &p : poursim::measure_torque_speed(full_drive(), 20.0, 4))
    TEST_ASSERT_TRUE(std::fabs(p.delivered - p.command) <= 0.03 * p.command);
}

static void test_motor_ShaftTorqueCheckSeesTheVoltageLimitBeyondBaseSpeed(void) {
  // the same measurement at 1.3× the base speed: the bus no longer carries the current, the torque falls short
  const poursim_config_t c = full_drive();
  const double delivered = poursim::measure_shaft_torque(c, 20.0, 1.3 * poursim::base_speed(c, 20.0));
  TEST_ASSERT_TRUE(20.0 - delivered > 0.03 * 20.0);
}

static std::string weights() { return std::string(POUR_SOURCE_DIR) + "/policy/weights.h"; }

static void test_motor_FluxBrakingKeepsThePourUnderTheBoardRating(void) {
  poursim::BusTrace b;
  std::string why;
  TEST_ASSERT_TRUE_MESSAGE(poursim::measure_pour_bus(full_drive(), weights(), 1, 3.0, &b, &why), why.c_str());
  TEST_ASSERT_TRUE(b.peak_vbus <= 25.2); // the 6S rating of the B-G431B-ESC1
  TEST_ASSERT_EQUAL_UINT32(0, b.faults);
  TEST_ASSERT_TRUE(b.poured > 0.95);
}

static void test_motor_WithoutFluxBrakingThePourOvervoltsAndTrips(void) {
  poursim_config_t c = full_drive();
  c.drive_regen = 0;
  poursim::BusTrace b;
  std::string why;
  TEST_ASSERT_TRUE_MESSAGE(poursim::measure_pour_bus(c, weights(), 1, 3.0, &b, &why), why.c_str());
  TEST_ASSERT_TRUE(b.peak_vbus > 28.0);
  TEST_ASSERT_TRUE((b.faults & POUR_DRIVE_FAULT_OVERVOLTAGE) != 0u);
}

// Constant torque (action a) for 1.5 s with fault f injected: the fault it latches, the bucket's motion over
// the last 0.5 s [rad], its tilt at the end [rad], and whether every observation stayed finite.
static unsigned run_fault(int f, double a, double *late_motion, double *theta_end, bool *finite) {
  poursim_config_t c = full_drive();
  c.drive_fault = f;
  char err[POURSIM_ERR_LEN];
  poursim_world_t *w = poursim_create(&c, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  poursim_obs_t o;
  double theta_1s = 0;
  *finite = true;
  for (int k = 0; k < 1500; ++k) {
    TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_step(w, a, &o));
    *finite = *finite && std::isfinite(o.theta) && std::isfinite(o.motor_torque);
    if (k == 999) theta_1s = o.theta;
  }
  *late_motion = std::fabs(o.theta - theta_1s);
  *theta_end = o.theta;
  poursim_drive_telemetry_t t;
  poursim_drive_telemetry(w, &t);
  poursim_destroy(w);
  return t.faults;
}

static void assert_fault_held(int f, unsigned expected) {
  double motion, theta;
  bool finite;
  const unsigned faults = run_fault(f, 0.4, &motion, &theta, &finite);
  TEST_ASSERT_EQUAL_HEX32(expected, faults);
  TEST_ASSERT_TRUE(motion < 1e-3); // held by the brake, not coasting
  TEST_ASSERT_TRUE(theta < 0.2);    // and caught early, near upright
  TEST_ASSERT_TRUE(finite);
}

static void test_motor_NoFaultWithoutInjection(void) {
  double motion, theta;
  bool finite;
  TEST_ASSERT_EQUAL_HEX32(0, run_fault(0, 0.4, &motion, &theta, &finite));
  TEST_ASSERT_TRUE(theta > 0.5); // the same command tilts the bucket well past where the faults held it
  TEST_ASSERT_TRUE(finite);
}

static void test_motor_OpenPhaseLatchesThePhaseFault(void) { assert_fault_held(1, POUR_DRIVE_FAULT_PHASE); }
// The board's amplifier reads at most 45.3 A out of the motor (its bias 2.057 V sits 1,542 counts under full
// scale, pour/board_facts.h): a short's current clips there, so the three no longer sum to zero and the phase
// check latches in the same period as the overcurrent.
constexpr unsigned kShortFaults = POUR_DRIVE_FAULT_OVERCURRENT | POUR_DRIVE_FAULT_PHASE;
static void test_motor_ShortedPhasesLatchTheOvercurrent(void) { assert_fault_held(2, kShortFaults); }
static void test_motor_ReversedEncoderLatchesTheDirectionFault(void) {
  assert_fault_held(3, POUR_DRIVE_FAULT_ENCODER_DIRECTION);
}
static void test_motor_BrokenAmplifierLatchesTheOffsetFault(void) {
  assert_fault_held(4, POUR_DRIVE_FAULT_CURRENT_OFFSET);
}

// A tilt at 0.5 rad/s by the firmware's core (a baseline through its pipeline) with fault f injected in the
// full drive: the drive's word as the core's input saw it, the core's faults and brake at the end, and how
// far the bucket moved from where the drive's fault first showed [rad] (0 if none did).
struct CoreFault {
  uint32_t drive_faults = 0;
  int trusted_at_fault = -1;
  uint16_t core_faults = 0;
  bool brake = false;
  double moved = 0.0;
};

static CoreFault run_core_fault(int f) {
  poursim_config_t c = full_drive();
  c.drive_fault = f;
  char err[POURSIM_ERR_LEN];
  poursim_world_t *w = poursim_create(&c, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  std::unique_ptr<poursim::Controller> ctl = poursim::make_rate_controller(0.5, c);
  ctl->reset(1);
  poursim_obs_t o;
  poursim_observe(w, &o);
  CoreFault r;
  double theta_fault = 0.0;
  for (int k = 0; k < 1500; ++k) {
    const double a = ctl->command(o);
    TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_set_brake(w, ctl->brake() ? 1 : 0));
    if (r.trusted_at_fault < 0 && o.drive_faults != 0u) {
      r.trusted_at_fault = o.drive_trusted;
      theta_fault = o.theta;
    }
    TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_step(w, a, &o));
    r.drive_faults = o.drive_faults;
  }
  r.core_faults = ctl->faults();
  r.brake = ctl->brake();
  r.moved = r.trusted_at_fault < 0 ? 0.0 : std::fabs(o.theta - theta_fault);
  poursim_destroy(w);
  return r;
}

static void test_motor_DriveFaultsReachTheCoreWhichHoldsTheBucket(void) {
  const struct {
    int fault;
    uint32_t bit;
  } cases[] = {{1, POUR_DRIVE_FAULT_PHASE}, {2, kShortFaults}, {3, POUR_DRIVE_FAULT_ENCODER_DIRECTION}};
  for (const auto &k : cases) {
    const CoreFault r = run_core_fault(k.fault);
    TEST_ASSERT_EQUAL_HEX32(k.bit, r.drive_faults);
    TEST_ASSERT_EQUAL_INT(0, r.trusted_at_fault); // the drive shorts its phases: not trusted to stop actively
    TEST_ASSERT_TRUE((r.core_faults & POUR_FAULT_DRIVE) != 0u);
    TEST_ASSERT_TRUE(r.brake);
    TEST_ASSERT_TRUE(r.moved < 10.0 * M_PI / 180.0);
  }
  const CoreFault none = run_core_fault(0);
  TEST_ASSERT_EQUAL_HEX32(0u, none.drive_faults);
  TEST_ASSERT_EQUAL_HEX16(0u, none.core_faults & POUR_FAULT_DRIVE);
}

static void test_motor_ConfigRefusesDriveKeysOutOfRange(void) {
  const char *bad[][2] = {{"drive", "2"}, {"drive_regen", "-1"}, {"drive_fault", "6"}, {"supply_voltage", "30"},
                          {"bus_capacitance", "0"}};
  for (const auto &kv : bad) {
    poursim_config_t c = poursim_default_config();
    char err[POURSIM_ERR_LEN] = "";
    const int rc = poursim_config_set(&c, kv[0], kv[1], err, sizeof err);
    const int rv = rc == POURSIM_OK ? poursim_config_validate(&c, err, sizeof err) : rc;
    TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, rv);
    TEST_ASSERT_NOT_NULL_MESSAGE(std::strstr(err, kv[0]), err);
  }
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_motor_CurrentStepMeetsTheBars);
  RUN_TEST(test_motor_CurrentStepCheckSeesAHalvedBandwidth);
  RUN_TEST(test_motor_ShaftTorqueFollowsTheCommandToBaseSpeed);
  RUN_TEST(test_motor_ShaftTorqueCheckSeesTheVoltageLimitBeyondBaseSpeed);
  RUN_TEST(test_motor_FluxBrakingKeepsThePourUnderTheBoardRating);
  RUN_TEST(test_motor_WithoutFluxBrakingThePourOvervoltsAndTrips);
  RUN_TEST(test_motor_NoFaultWithoutInjection);
  RUN_TEST(test_motor_OpenPhaseLatchesThePhaseFault);
  RUN_TEST(test_motor_ShortedPhasesLatchTheOvercurrent);
  RUN_TEST(test_motor_ReversedEncoderLatchesTheDirectionFault);
  RUN_TEST(test_motor_BrokenAmplifierLatchesTheOffsetFault);
  RUN_TEST(test_motor_DriveFaultsReachTheCoreWhichHoldsTheBucket);
  RUN_TEST(test_motor_ConfigRefusesDriveKeysOutOfRange);
  return UNITY_END();
}
