/* SPDX-License-Identifier: MIT */
/* The board's protection alone: derating before the fault, the faults' debounce and latch, ClearErrors
 * only once the cause is gone, the reaction by trust, the brake's engagement time, the sensors' anchor. */
#include <string.h>

#include "protect.h"
#include "unity.h"

static pour_protect_t p;
static pour_protect_input_t in;
static pour_protect_output_t out;

void setUp(void) {
  const pour_protect_config_t c = pour_protect_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_protect_init(&p, &c));
  memset(&in, 0, sizeof in);
  in.vbus_mv = 24000u;
  in.temp_mdegc = 40000;
  in.calibration_valid = true;
  in.output_fresh = true;
}

void tearDown(void) {}

static void step(unsigned n) {
  for (unsigned i = 0; i < n; ++i) {
    pour_protect_step(&p, &in, &out);
  }
}

static void test_protect_DeratesBeforeItFaults(void) {
  step(1);
  TEST_ASSERT_EQUAL_INT16(32767, out.torque_scale);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_RUN, out.action);
  in.vbus_mv = 19000u; /* halfway between 18 V and 20 V */
  step(5);
  TEST_ASSERT_INT16_WITHIN(2, 16383, out.torque_scale);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
  in.vbus_mv = 24000u;
  in.temp_mdegc = 95000; /* a quarter of the 80..100 °C ramp left */
  step(1);
  TEST_ASSERT_INT16_WITHIN(2, 8191, out.torque_scale);
  in.temp_mdegc = 40000;
  in.vbus_mv = 27000u;
  step(1);
  TEST_ASSERT_INT16_WITHIN(2, 16383, out.torque_scale);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
}

static void test_protect_BusFaultsAreDebouncedThenLatched(void) {
  in.vbus_mv = 17000u;
  step(2);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults); /* two ticks: a glitch */
  step(1);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_UNDERVOLTAGE, out.faults);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_ACTIVE_STOP, out.action);
  TEST_ASSERT_EQUAL_INT16(32767, out.torque_scale); /* the stop gets what the drive has */
  in.vbus_mv = 24000u;
  step(10);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_UNDERVOLTAGE, out.faults); /* latched: the bus came back */
}

static void test_protect_ClearsOnlyOnceTheCauseIsGone(void) {
  in.hw_overcurrent = true;
  step(1);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_HW_OVERCURRENT, out.faults);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, out.action);
  in.clear = true;
  step(1);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_HW_OVERCURRENT, out.faults); /* still tripping: refused */
  in.hw_overcurrent = false;
  step(1);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_RUN, out.action);
  TEST_ASSERT_FALSE(out.brake);
}

static void test_protect_HoldsOnTheBrakeAfterItsEngagementTime(void) {
  in.temp_mdegc = 101000;
  step(1);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_ACTIVE_STOP, out.action);
  step(29);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_ACTIVE_STOP, out.action);
  step(1);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_HELD, out.action);
}

static void test_protect_AnUntrustedFaultShortsTheRestOfTheStop(void) {
  in.temp_mdegc = 101000;
  step(5);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_ACTIVE_STOP, out.action);
  in.vbus_mv = 29000u;
  step(3);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_OVERTEMP | POUR_DRIVE_FAULT_OVERVOLTAGE, out.faults);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, out.action);
}

static void test_protect_SensorsDisagreeingBeyondTheBacklash(void) {
  in.motor_urad = 1000;
  in.output_urad = 700000; /* the absolute angle at start: the anchor */
  step(1);
  in.motor_urad = 101000;
  in.output_urad = 810000; /* 10 mrad apart: within the 17.5 mrad backlash */
  step(10);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
  in.output_urad = 830000; /* 30 mrad */
  in.output_fresh = false;
  step(10);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults); /* no fresh sample, no verdict */
  in.output_fresh = true;
  step(2);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
  step(1);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_ENCODER_MISMATCH, out.faults);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, out.action);
}

static void test_protect_WithoutCalibrationTheBrakeIsNeverReleased(void) {
  in.calibration_valid = false;
  step(1);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CALIBRATION, out.faults);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_HELD, out.action);
  TEST_ASSERT_TRUE(out.brake);
}

static void test_protect_init_RefusesThresholdsOutOfOrder(void) {
  pour_protect_config_t c = pour_protect_default_config();
  c.uv_fault_mv = c.uv_derate_mv;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_protect_init(&p, &c));
  c = pour_protect_default_config();
  c.temp_fault_mdegc = c.temp_derate_mdegc - 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_protect_init(&p, &c));
  c = pour_protect_default_config();
  c.mismatch_ticks = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_protect_init(&p, &c));
}

static void test_protect_AFaultTheLoopLatchedItselfShortsEvenATrustedOne(void) {
  in.loop_faults = POUR_DRIVE_FAULT_UNDERVOLTAGE; /* the loop's own per-period trip: it shorts its phases */
  step(1);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_UNDERVOLTAGE, out.faults);
  TEST_ASSERT_EQUAL_INT(POUR_PROTECT_SHORT, out.action);
  TEST_ASSERT_TRUE(out.brake);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_protect_DeratesBeforeItFaults);
  RUN_TEST(test_protect_BusFaultsAreDebouncedThenLatched);
  RUN_TEST(test_protect_ClearsOnlyOnceTheCauseIsGone);
  RUN_TEST(test_protect_HoldsOnTheBrakeAfterItsEngagementTime);
  RUN_TEST(test_protect_AnUntrustedFaultShortsTheRestOfTheStop);
  RUN_TEST(test_protect_SensorsDisagreeingBeyondTheBacklash);
  RUN_TEST(test_protect_WithoutCalibrationTheBrakeIsNeverReleased);
  RUN_TEST(test_protect_AFaultTheLoopLatchedItselfShortsEvenATrustedOne);
  RUN_TEST(test_protect_init_RefusesThresholdsOutOfOrder);
  return UNITY_END();
}
