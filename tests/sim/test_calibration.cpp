// SPDX-License-Identifier: MIT
// The drive's self-calibration (pour/motor_cal.h) closed against host_sim's motor model, the one the full
// drive runs: a motor whose R, L, pole pairs, encoder offset and direction all differ from the firmware's
// configuration is measured within the stated tolerances and the motion stays within the stated range; each
// bad result (an open phase, an unplugged encoder, motion beyond the range, a fault, an abort) is named and
// ends with the brake engaged. The empty bucket on its bearing: a rigid inertia with viscous friction (its
// centre of mass on the axis: no gravity torque), stopped dead while the brake is engaged.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "foc_drive.hpp"
#include "poursim/poursim.h"

extern "C" {
#include "calibration_flow.h"
#include "flash_page_file.h"
#include "unity.h"
}

void setUp(void) {}
void tearDown(void) {}

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kInertia = 0.038; // [kg·m²] at the output: the 2 kg bucket about its centre, the rotor through 1:20
constexpr double kFriction = 2.0;  // [N·m·s/rad] at the output: bearings and gearbox, assumed

struct Run {
  pour_motor_cal_status_t status = POUR_MOTOR_CAL_NONE;
  pour_motor_cal_result_t result{};
  double peak_motion = 0;   // largest |output angle| from the start [rad]
  double seconds = 0;       // how long the sequence ran
  bool brake_at_end = false; // the brake requested in the period the sequence ended
  bool released_while_measuring = true;
  uint16_t faults = 0;
};

// A motor unlike the firmware's default (8 pole pairs, 0.2865 Ω, 150.5 µH, encoder aligned, counting up).
poursim::MotorParams other_motor(const poursim::FocDrive &foc) {
  poursim::MotorParams p = poursim::motor_params(foc.firmware_config(), poursim_default_config());
  p.r_phase = 0.45;
  p.ld = p.lq = 220e-6;
  p.pole_pairs = 4;
  p.flux = 0.0404 / (1.5 * p.pole_pairs); // the same torque constant
  p.encoder_zero = 0.3;                   // electrical offset 4 × 0.3 rad
  p.encoder_sign = -1;
  return p;
}

// Runs the sequence from RUN at rest; abort_at > 0: a stop that many periods in.
Run run(poursim::FocDrive &foc, long abort_at = 0) {
  Run r;
  TEST_ASSERT_EQUAL_INT(POUR_OK, foc.calibrate());
  const double ts = 1.0 / foc.firmware_config().pwm_hz;
  double omega = 0, theta = 0;
  for (long n = 0; n < 5L * 20000; ++n) {
    if (abort_at > 0 && n == abort_at) foc.abort_calibration();
    if (n % 20 == 0) foc.command(0.0, omega, 1e-3); // the 1 kHz tick: the I²t budget
    const double tau = foc.period(omega);
    const bool brake = foc.output().brake != 0;
    if (foc.drive().state != POUR_DRIVE_MEASURING) {
      r.brake_at_end = brake;
      r.seconds = static_cast<double>(n) * ts;
      break;
    }
    if (brake) r.released_while_measuring = false;
    omega = brake ? 0.0 : omega + ts * (tau - kFriction * omega) / kInertia;
    theta += omega * ts;
    r.peak_motion = std::max(r.peak_motion, std::fabs(theta));
  }
  r.status = pour_drive_calibration(&foc.drive(), &r.result);
  r.faults = foc.drive().faults;
  return r;
}

poursim::FocDrive drive_with(const poursim::MotorParams *motor, int fault) {
  poursim_config_t c = poursim_default_config();
  c.drive = 1;
  c.drive_fault = fault;
  poursim::FocDrive foc;
  foc.reset(c, 7);
  if (motor != nullptr) foc.set_motor(*motor, 7);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, foc.drive().state);
  return foc;
}

double offset_error_deg(uint16_t measured, double expected_rad) {
  const double expected = std::fmod(expected_rad / (2 * kPi) * 65536.0, 65536.0);
  double d = measured - expected;
  while (d > 32768) d -= 65536;
  while (d < -32768) d += 65536;
  return std::fabs(d) * 360.0 / 65536.0;
}

} // namespace

static void test_motor_cal_MeasuresAMotorUnlikeTheConfiguration(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  const poursim::MotorParams p = other_motor(foc);
  foc.set_motor(p, 7);
  const Run r = run(foc);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_OK, r.status);
  TEST_ASSERT_EQUAL_UINT16(0, r.faults);
  TEST_ASSERT_TRUE(r.released_while_measuring);
  TEST_ASSERT_TRUE(r.brake_at_end);
  const double r_ohm = r.result.r_phase_uohm * 1e-6, l_h = r.result.l_phase_nh * 1e-9;
  const double off = offset_error_deg(r.result.electrical_offset, p.pole_pairs * p.encoder_zero);
  printf("R %.4f ohm (model %.4f), L %.1f uH (model %.1f), pole pairs %u, direction %d, offset error %.2f deg "
         "electrical, peak output motion %.2f deg, %.2f s\n",
         r_ohm, p.r_phase, l_h * 1e6, p.ld * 1e6, (unsigned)r.result.pole_pairs, (int)r.result.encoder_direction, off,
         r.peak_motion * 180 / kPi, r.seconds);
  TEST_ASSERT_TRUE(std::fabs(r_ohm / p.r_phase - 1.0) <= 0.05);
  TEST_ASSERT_TRUE(std::fabs(l_h / p.ld - 1.0) <= 0.05);
  TEST_ASSERT_EQUAL_UINT32(4, r.result.pole_pairs);
  TEST_ASSERT_EQUAL_INT32(-1, r.result.encoder_direction);
  TEST_ASSERT_TRUE(off <= 3.0);
  TEST_ASSERT_TRUE(r.peak_motion <= 10.0 * kPi / 180);
  // applied: the drive runs with them, at zero current
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, foc.drive().state);
  const pour_drive_config_t &c = foc.drive().config;
  TEST_ASSERT_EQUAL_UINT32(r.result.r_phase_uohm, c.r_phase_uohm);
  TEST_ASSERT_EQUAL_UINT32(4, c.pole_pairs);
  TEST_ASSERT_EQUAL_UINT32(1, c.encoder_reversed);
  TEST_ASSERT_EQUAL_UINT16(r.result.electrical_offset, c.encoder_offset);
}

static void test_motor_cal_CalibratedDriveDeliversTheCommandedTorque(void) {
  // With the configuration's pole pairs, offset and direction the loop would push the wrong way; measured, the
  // commanded torque arrives at the output (the rotor held still).
  poursim::FocDrive foc = drive_with(nullptr, 0);
  foc.set_motor(other_motor(foc), 7);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_OK, run(foc).status);
  for (int k = 0; k < 400 && foc.drive().state != POUR_DRIVE_RUN; ++k) foc.period(0.0);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, foc.drive().state);
  double tau = 0;
  for (int ms = 0; ms < 50; ++ms) tau = foc.step(2.0, 0.0, 1e-3);
  TEST_ASSERT_TRUE(std::fabs(tau - 2.0) <= 0.05 * 2.0);
  TEST_ASSERT_EQUAL_UINT16(0, foc.drive().faults);
}

static void test_motor_cal_TheDefaultMotorMeasuresAsConfigured(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  const pour_drive_config_t fw = foc.firmware_config();
  const Run r = run(foc);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_OK, r.status);
  TEST_ASSERT_TRUE(std::fabs(r.result.r_phase_uohm / (double)fw.r_phase_uohm - 1.0) <= 0.05);
  TEST_ASSERT_TRUE(std::fabs(r.result.l_phase_nh / (double)fw.ld_nh - 1.0) <= 0.05);
  TEST_ASSERT_EQUAL_UINT32(fw.pole_pairs, r.result.pole_pairs);
  TEST_ASSERT_EQUAL_INT32(1, r.result.encoder_direction);
  TEST_ASSERT_TRUE(offset_error_deg(r.result.electrical_offset, 0.0) <= 3.0);
  // 8 pole pairs through 1:20: an electrical turn is 2.25° of output
  printf("default motor: R %.4f ohm, L %.1f uH, pole pairs %u, offset error %.2f deg, peak output motion %.2f deg\n",
         r.result.r_phase_uohm * 1e-6, r.result.l_phase_nh * 1e-3, (unsigned)r.result.pole_pairs,
         offset_error_deg(r.result.electrical_offset, 0.0), r.peak_motion * 180 / kPi);
  TEST_ASSERT_TRUE(r.peak_motion <= 5.0 * kPi / 180);
}

// The drive's heat [A²·s] from its per-unit Q30·ms (pour_drive_init's scale).
double heat_a2s(const pour_drive_t &d) {
  return static_cast<double>(d.heat_q30ms) * (POUR_DRIVE_I_BASE_MA / 1000.0) * (POUR_DRIVE_I_BASE_MA / 1000.0) /
         (1000.0 * 1073741824.0);
}

// The sequence's 4 A for 3.1 s heats the motor as a torque would; started with less of the I²t budget left
// than a run takes, it ends in the I²t fault, held.
static void test_motor_cal_TheSequenceSpendsTheI2tBudgetAndAHotStartEndsInTheFault(void) {
  poursim::FocDrive cold = drive_with(nullptr, 0);
  const Run c = run(cold);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_OK, c.status);
  const double spent = heat_a2s(cold.drive());
  const double budget = cold.firmware_config().i2t_budget_a2s;
  poursim::FocDrive hot = drive_with(nullptr, 0);
  const int64_t five_a2s = hot.drive().i2t_budget_q30ms * 5 / static_cast<int64_t>(budget);
  hot.drive().heat_q30ms = hot.drive().i2t_budget_q30ms - five_a2s; // 5 A²s left
  const Run h = run(hot);
  printf("calibration heat: %.1f of %.0f A2s a run; started with 5 A2s left: status %d after %.2f s, faults 0x%04x, "
         "brake %d\n", spent, budget, (int)h.status, h.seconds, (unsigned)h.faults, (int)h.brake_at_end);
  TEST_ASSERT_TRUE(spent > 8.0 && spent < 30.0);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_ABORTED, h.status);
  TEST_ASSERT_BITS_HIGH(POUR_DRIVE_FAULT_I2T | POUR_DRIVE_FAULT_CALIBRATION, h.faults);
  TEST_ASSERT_TRUE(h.brake_at_end);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, hot.drive().state);
  TEST_ASSERT_TRUE(h.seconds < c.seconds);
  TEST_ASSERT_TRUE(h.peak_motion <= 10.0 * kPi / 180);
}

static void assert_refused(const Run &r, pour_motor_cal_status_t why) {
  printf("refused %d after %.3f s, peak output motion %.2f deg\n", (int)r.status, r.seconds, r.peak_motion * 180 / kPi);
  TEST_ASSERT_EQUAL_INT(why, r.status);
  TEST_ASSERT_TRUE(r.brake_at_end);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULT_CALIBRATION, r.faults & POUR_DRIVE_FAULT_CALIBRATION);
  TEST_ASSERT_TRUE(r.peak_motion <= 10.0 * kPi / 180 + 1e-3);
}

static void test_motor_cal_AnOpenPhaseIsAResistanceOutOfRange(void) {
  poursim::FocDrive foc = drive_with(nullptr, 1); // phase c open: no current along β
  assert_refused(run(foc), POUR_MOTOR_CAL_RESISTANCE);
}

static void test_motor_cal_AnUnpluggedEncoderIsNamed(void) {
  poursim::FocDrive foc = drive_with(nullptr, 5);
  assert_refused(run(foc), POUR_MOTOR_CAL_NO_ENCODER);
}

static void test_motor_cal_AnInductanceBelowAnyMotorsIsRefused(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  poursim::MotorParams p = other_motor(foc);
  // an air-core winding, or the leads shorted past the motor; with R·Ts/2 = 5 µH (what a period's full settling
  // reads as) below the 10 µH floor
  p.r_phase = 0.2;
  p.ld = p.lq = 3e-6;
  foc.set_motor(p, 7);
  assert_refused(run(foc), POUR_MOTOR_CAL_INDUCTANCE);
}

static void test_motor_cal_AResultTheConfigurationRefusesLeavesItsMotor(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  foc.set_motor(other_motor(foc), 7);
  // Injected: a configuration that its check refuses once the measured numbers are tried in it.
  foc.drive().config.bandwidth_rad_s = 0u;
  const pour_drive_config_t before = foc.drive().config;
  const Run r = run(foc);
  assert_refused(r, POUR_MOTOR_CAL_INDUCTANCE);
  TEST_ASSERT_NOT_EQUAL(before.pole_pairs, r.result.pole_pairs); // a motor unlike the configuration's was measured
  const pour_drive_config_t &after = foc.drive().config;
  TEST_ASSERT_EQUAL_UINT32(before.r_phase_uohm, after.r_phase_uohm);
  TEST_ASSERT_EQUAL_UINT32(before.ld_nh, after.ld_nh);
  TEST_ASSERT_EQUAL_UINT32(before.lq_nh, after.lq_nh);
  TEST_ASSERT_EQUAL_UINT32(before.pole_pairs, after.pole_pairs);
  TEST_ASSERT_EQUAL_UINT32(before.encoder_reversed, after.encoder_reversed);
  TEST_ASSERT_EQUAL_UINT16(before.encoder_offset, after.encoder_offset);
}

static void test_motor_cal_MorePolePairsThanAnyMotorIsRefused(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  poursim::MotorParams p = other_motor(foc);
  p.pole_pairs = 33; // 124 counts an electrical turn: more than the 32 the drive supports
  p.flux = 0.0404 / (1.5 * p.pole_pairs);
  foc.set_motor(p, 7);
  assert_refused(run(foc), POUR_MOTOR_CAL_POLE_PAIRS);
}

static void test_motor_cal_MotionBeyondTheRangeStopsTheSequence(void) {
  // one pole pair through 1:20: an electrical turn would be 18° of output, the range is 10°
  poursim::FocDrive foc = drive_with(nullptr, 0);
  poursim::MotorParams p = other_motor(foc);
  p.pole_pairs = 1;
  p.flux = 0.0404 / 1.5;
  foc.set_motor(p, 7);
  const Run r = run(foc);
  assert_refused(r, POUR_MOTOR_CAL_MOTION);
  printf("motion range: stopped at %.2f deg of output after %.3f s\n", r.peak_motion * 180 / kPi, r.seconds);
  TEST_ASSERT_TRUE(r.peak_motion >= 9.0 * kPi / 180); // it did get there: the check is what stopped it
}

static void test_motor_cal_AFaultEndsItHeld(void) {
  poursim::FocDrive foc = drive_with(nullptr, 2); // phases a and b shorted: the test current trips
  const Run r = run(foc);
  assert_refused(r, POUR_MOTOR_CAL_ABORTED);
  TEST_ASSERT_TRUE((r.faults & (POUR_DRIVE_FAULT_OVERCURRENT | POUR_DRIVE_FAULT_PHASE)) != 0);
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, foc.calibrate()); // a fault of the power stage stands in its way
}

static void test_motor_cal_AStopEndsItHeld(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  assert_refused(run(foc, 30000), POUR_MOTOR_CAL_ABORTED); // in the forward turn
}

static void test_motor_cal_RefusedWhileRunningAndRetriedAfterAStop(void) {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  TEST_ASSERT_EQUAL_INT(POUR_OK, foc.calibrate());
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, foc.calibrate()); // already measuring
  foc.abort_calibration();
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, foc.drive().state);
  TEST_ASSERT_EQUAL_UINT16(POUR_DRIVE_FAULT_CALIBRATION, foc.drive().faults);
  // uncalibrated is the one fault a calibration starts from: the retry runs to the end
  const Run r = run(foc);
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_OK, r.status);
  TEST_ASSERT_EQUAL_UINT16(0, foc.drive().faults);
}

// The board's flow around it, tick by tick as main.c runs it: CalibrationStart frames into the CAN node, the
// core's mode, the flow, the node's frames out, and the 20 current-loop periods of each millisecond.
struct Bench {
  poursim::FocDrive foc = drive_with(nullptr, 0);
  pour_can_node_t node{};
  pour_calibration_flow_t flow{};
  double omega = 0, theta = 0, peak = 0;
  std::vector<pour_can_calibration_result_t> results; // every CalibrationResult sent
  bool released_outside = false; // the brake released while the flow says nothing runs

  Bench() {
    flash_page_file_reset();
    pour_can_node_config_t nc = pour_can_node_default_config();
    nc.can_calibrate = true;
    nc.identity.init_status = (int8_t)POUR_ECALIBRATION;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &nc));
    pour_calibration_t none{};
    pour_calibration_flow_init(&flow, pour_calibration_load(&f, &none), nullptr);
    TEST_ASSERT_EQUAL_INT(POUR_CAL_EMPTY, flow.stored);
  }
  void start() {
    pour_can_frame_t fr;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(0, POUR_CAN_CMD_CALIBRATION_START, &fr));
    TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &fr));
  }
  void tick(pour_mode_t mode) {
    pour_control_input_t in;
    pour_can_node_begin_tick(&node, &in);
    const bool measuring = pour_calibration_flow_tick(&flow, &node, &foc.drive(), (uint8_t)mode, &f);
    pour_control_output_t out{};
    out.mode = (uint8_t)mode;
    pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
    const uint8_t n = pour_can_node_end_tick(&node, &out, 0, tx);
    for (uint8_t k = 0; k < n; ++k) {
      pour_can_calibration_result_t r;
      if (pour_can_unpack_calibration_result(&tx[k], &r) == POUR_CAN_RX_OK) results.push_back(r);
    }
    for (int p = 0; p < 20; ++p) {
      const double tau = foc.period(omega);
      const bool brake = foc.output().brake != 0 || !measuring;
      if (!brake && !measuring) released_outside = true;
      omega = brake ? 0.0 : omega + 5e-5 * (tau - kFriction * omega) / kInertia;
      theta += omega * 5e-5;
      peak = std::max(peak, std::fabs(theta));
    }
  }
};

static void test_calibration_flow_AGoodResultIsStoredAndTheBoardIsCalibrated(void) {
  Bench b;
  b.start();
  for (int ms = 0; ms < 4000; ++ms) b.tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_size_t(2, b.results.size());
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, b.results[0].status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_EMPTY, b.results[0].stored);
  const pour_can_calibration_result_t &done = b.results[1];
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, done.status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, done.stored);
  TEST_ASSERT_EQUAL_UINT8(8, done.pole_pairs);
  TEST_ASSERT_EQUAL_UINT8(0, done.encoder_reversed);
  TEST_ASSERT_TRUE(std::abs(done.resistance_mohm - 287) <= 14);
  TEST_ASSERT_TRUE(std::abs(done.inductance_uh - 151) <= 8);
  // in flash, as a reboot would load it; Identity no longer says uncalibrated
  pour_calibration_t got{};
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_load(&f, &got));
  TEST_ASSERT_EQUAL_UINT32(b.foc.drive().config.r_phase_uohm, got.r_phase_uohm);
  TEST_ASSERT_EQUAL_INT8(POUR_OK, b.node.config.identity.init_status);
  TEST_ASSERT_FALSE(b.released_outside);
  TEST_ASSERT_TRUE(b.peak <= 10.0 * kPi / 180);
}

static void test_calibration_flow_AFailedFlashWriteIsReported(void) {
  Bench b;
  regs[POUR_FLASH_SR] = 1u << 4; // WRPERR: the page is write-protected
  b.start();
  for (int ms = 0; ms < 4000; ++ms) b.tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_size_t(2, b.results.size());
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_WRITE_FAILED, b.results[1].status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_WRITE_FAILED, b.results[1].stored);
  TEST_ASSERT_EQUAL_INT8(POUR_ECALIBRATION, b.node.config.identity.init_status); // still uncalibrated
}

static void test_calibration_flow_TheEstopEndsItHeldAndSaysSo(void) {
  Bench b;
  b.start();
  for (int ms = 0; ms < 1500; ++ms) b.tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_MEASURING, b.foc.drive().state);
  b.tick(POUR_MODE_ESTOP);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, b.foc.drive().state);
  TEST_ASSERT_EQUAL_UINT8(1, b.foc.output().brake);
  b.tick(POUR_MODE_ESTOP);
  TEST_ASSERT_EQUAL_size_t(2, b.results.size());
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_ABORTED, b.results[1].status);
  TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFFu, page[0]); // nothing stored
  // a start while the e-stop is asserted: refused by name, the drive left as it is
  b.start();
  b.tick(POUR_MODE_ESTOP);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_ESTOP, b.results.back().status);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, b.foc.drive().state);
}

static void test_calibration_flow_ABadResultIsNamedOnTheBus(void) {
  Bench b;
  poursim::MotorParams p = other_motor(b.foc);
  p.pole_pairs = 1;
  p.flux = 0.0404 / 1.5;
  b.foc.set_motor(p, 7);
  b.start();
  for (int ms = 0; ms < 4000; ++ms) b.tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_size_t(2, b.results.size());
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MOTION_RANGE, b.results[1].status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_EMPTY, b.results[1].stored);
}

static void test_calibration_flow_RefusedInRun(void) {
  Bench b;
  b.start();
  b.tick(POUR_MODE_RUN);
  TEST_ASSERT_EQUAL_size_t(1, b.results.size());
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_RUNNING, b.results[0].status);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, b.foc.drive().state);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_motor_cal_MeasuresAMotorUnlikeTheConfiguration);
  RUN_TEST(test_motor_cal_CalibratedDriveDeliversTheCommandedTorque);
  RUN_TEST(test_motor_cal_TheDefaultMotorMeasuresAsConfigured);
  RUN_TEST(test_motor_cal_AnOpenPhaseIsAResistanceOutOfRange);
  RUN_TEST(test_motor_cal_AnUnpluggedEncoderIsNamed);
  RUN_TEST(test_motor_cal_AnInductanceBelowAnyMotorsIsRefused);
  RUN_TEST(test_motor_cal_AResultTheConfigurationRefusesLeavesItsMotor);
  RUN_TEST(test_motor_cal_MorePolePairsThanAnyMotorIsRefused);
  RUN_TEST(test_motor_cal_MotionBeyondTheRangeStopsTheSequence);
  RUN_TEST(test_motor_cal_AFaultEndsItHeld);
  RUN_TEST(test_motor_cal_AStopEndsItHeld);
  RUN_TEST(test_motor_cal_RefusedWhileRunningAndRetriedAfterAStop);
  RUN_TEST(test_motor_cal_TheSequenceSpendsTheI2tBudgetAndAHotStartEndsInTheFault);
  RUN_TEST(test_calibration_flow_AGoodResultIsStoredAndTheBoardIsCalibrated);
  RUN_TEST(test_calibration_flow_AFailedFlashWriteIsReported);
  RUN_TEST(test_calibration_flow_TheEstopEndsItHeldAndSaysSo);
  RUN_TEST(test_calibration_flow_ABadResultIsNamedOnTheBus);
  RUN_TEST(test_calibration_flow_RefusedInRun);
  return UNITY_END();
}
