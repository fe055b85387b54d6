/* SPDX-License-Identifier: MIT */
/* The drive's current loop against tests/golden/motor_golden.h (recorded on the host by gen_motor_golden):
 * the same compares, currents and flags on every period, on the host and on the emulated Cortex-M4. */
#include "drive_script.h"
#include "motor_golden.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static pour_drive_golden_t run[POUR_DRIVE_SCRIPT_PERIODS];

static void test_drive_golden_EveryPeriodMatchesTheRecording(void) {
  TEST_ASSERT_EQUAL_INT(0, pour_drive_script_run(run));
  for (unsigned k = 0; k < POUR_DRIVE_SCRIPT_PERIODS; ++k) {
    for (int p = 0; p < 3; ++p) TEST_ASSERT_EQUAL_UINT16(pour_motor_golden[k].compare[p], run[k].compare[p]);
    TEST_ASSERT_EQUAL_INT16(pour_motor_golden[k].id, run[k].id);
    TEST_ASSERT_EQUAL_INT16(pour_motor_golden[k].iq, run[k].iq);
    TEST_ASSERT_EQUAL_HEX16(pour_motor_golden[k].limits, run[k].limits);
    TEST_ASSERT_EQUAL_HEX16(pour_motor_golden[k].faults, run[k].faults);
  }
}

static void test_drive_golden_TheScriptExercisesTheLimits(void) {
  /* flux braking, the voltage limit and the current limit all occur, and no fault stops the run */
  unsigned flags = 0;
  for (unsigned k = 0; k < POUR_DRIVE_SCRIPT_PERIODS; ++k) flags |= pour_motor_golden[k].limits;
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_LIMIT_FLUX_BRAKE | POUR_DRIVE_LIMIT_VOLTAGE | POUR_DRIVE_LIMIT_CURRENT,
                          flags & 0x07u);
  TEST_ASSERT_EQUAL_HEX16(0, pour_motor_golden[POUR_DRIVE_SCRIPT_PERIODS - 1].faults);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_drive_golden_EveryPeriodMatchesTheRecording);
  RUN_TEST(test_drive_golden_TheScriptExercisesTheLimits);
  return UNITY_END();
}
