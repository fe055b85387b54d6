// SPDX-License-Identifier: MIT
// The firmware's reading of the board's analog chain against the board as ST built it: host_sim's motor model
// takes its shunt amplifiers (bias, gain, sign) and bus divider from pour/board_facts.h, the firmware's drive
// (the same fixed-point code the board runs) reads them through its own configuration. Its offsets must fall
// in the band, its currents must have the board's sign (a wrong sign is positive feedback: the loop runs away),
// its bus voltage must be the model's. Each check is shown to fail on the old belief (mid-rail bias, the
// current's sign the other way, the 19.17 divider).
#include <cmath>
#include <cstdio>

#include "foc_drive.hpp"
#include "poursim/poursim.h"

extern "C" {
#include "pour/board_facts.h"
#include "unity.h"
}

void setUp(void) {}
void tearDown(void) {}

namespace {

constexpr double kTau = 2.0; // [N·m] at the output, well inside the drive's limit

poursim_config_t rig() {
  poursim_config_t c = poursim_default_config();
  c.drive_regen = 1;
  return c;
}

// The mean output torque of 50 ms held at rest with kTau commanded, and the faults it latched.
double hold(poursim::FocDrive &foc, uint16_t *faults) {
  double sum = 0.0;
  const int n = 50;
  for (int k = 0; k < n; ++k) sum += foc.step(kTau, 0.0, 1e-3);
  *faults = foc.telemetry().faults;
  return sum / n;
}

} // namespace

// The firmware's offsets are measured on the board's bias (2.057 V) and accepted; its torque, through the
// board's sign, is the one commanded; the bus it reads is the model's.
static void test_analog_chain_TheFirmwareReadsTheBoardAsBuilt(void) {
  poursim::FocDrive foc;
  foc.reset(rig(), 11u);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, foc.drive().state);
  for (int k = 0; k < 3; ++k) {
    TEST_ASSERT_INT_WITHIN(POUR_BOARD_OFFSET_TOLERANCE_COUNTS, POUR_BOARD_OFFSET_NOMINAL_COUNTS, foc.drive().sense.offset[k]);
  }
  uint16_t faults = 0;
  const double tau = hold(foc, &faults);
  TEST_ASSERT_EQUAL_HEX16(0u, faults);
  TEST_ASSERT_DOUBLE_WITHIN(0.1 * kTau, kTau, tau);
  const double vbus = foc.output().vbus * (POUR_DRIVE_V_BASE_MV * 1e-3) / 32768.0;
  TEST_ASSERT_DOUBLE_WITHIN(0.02 * foc.model().vbus(), foc.model().vbus(), vbus);
  printf("chain: offsets %u %u %u counts (board %d +- %d), torque %.3f N.m of %.3f, bus %.2f V read of %.2f V\n",
         foc.drive().sense.offset[0], foc.drive().sense.offset[1], foc.drive().sense.offset[2],
         POUR_BOARD_OFFSET_NOMINAL_COUNTS, POUR_BOARD_OFFSET_TOLERANCE_COUNTS, tau, kTau, vbus, foc.model().vbus());
}

// A board whose amplifiers rose with current into the motor (the old model, the sign the firmware had): the
// firmware, reading the board's sign, now feeds back positively, and the drive trips rather than follow.
static void test_analog_chain_ACurrentOfTheOtherSignIsCaught(void) {
  poursim::FocDrive foc;
  foc.reset(rig(), 12u);
  poursim::MotorParams p = poursim::motor_params(foc.firmware_config(), rig());
  p.amp_gain = -p.amp_gain;
  foc.set_motor(p, 12u);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, foc.drive().state);
  uint16_t faults = 0;
  const double tau = hold(foc, &faults);
  TEST_ASSERT_TRUE(faults != 0u || std::fabs(tau - kTau) > 0.5 * kTau);
  printf("chain, amplifier of the other sign: faults 0x%04x, torque %.3f N.m of %.3f\n", faults, tau, kTau);
}

// Runs a drive of configuration c on the board's chain for the offsets and 20 periods more; its faults.
static uint16_t boot(const pour_drive_config_t &c, uint32_t seed) {
  pour_drive_t drv{};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_drive_init(&drv, &c));
  pour_drive_output_t out{};
  poursim::MotorModel model;
  model.reset(poursim::motor_params(c, rig()), seed, poursim::MotorFault::None);
  for (int k = 0; k < POUR_CURRENT_SENSE_CAL_SAMPLES + 20; ++k) {
    const poursim::MotorSample s = model.sample();
    const pour_drive_sample_t in = {{s.adc_phase[0], s.adc_phase[1], s.adc_phase[2]}, s.adc_vbus, s.encoder};
    pour_drive_isr(&drv, &in, &out);
  }
  return out.faults;
}

// The old belief: the bias at mid-rail (2048 +- 160 counts) refuses a healthy board's offsets by name
// (CURRENT_OFFSET), and the 19.17 divider reads the 24 V bus as 44 V (OVERVOLTAGE); the board's own numbers
// boot clean.
static void test_analog_chain_TheOldOffsetAndDividerAreRefused(void) {
  const pour_drive_config_t board = pour_drive_default_config();
  TEST_ASSERT_EQUAL_HEX16(0u, boot(board, 13u));
  pour_drive_config_t old = board;
  old.offset_nominal = 2048u;
  old.offset_tolerance = 160u;
  const uint16_t offset_faults = boot(old, 13u);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, offset_faults);
  old = board;
  old.vbus_divider_milli = 19170u;
  const uint16_t divider_faults = boot(old, 13u);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_OVERVOLTAGE, divider_faults);
  printf("chain, old belief: mid-rail offsets -> faults 0x%04x; divider 19.17 -> faults 0x%04x\n", offset_faults,
         divider_faults);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_analog_chain_TheFirmwareReadsTheBoardAsBuilt);
  RUN_TEST(test_analog_chain_ACurrentOfTheOtherSignIsCaught);
  RUN_TEST(test_analog_chain_TheOldOffsetAndDividerAreRefused);
  return UNITY_END();
}
