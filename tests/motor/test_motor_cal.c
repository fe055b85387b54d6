/* SPDX-License-Identifier: MIT */
/* The self-calibration's sequence on its own, with scripted currents and counts (the closed loop against the
 * motor model is tests/sim/test_motor_cal.cpp): its configuration's ranges, and the refusals that need no
 * motor: no current at all, an encoder that jumps beyond the range. */
#include "pour/motor_cal.h"
#include "unity.h"

static pour_motor_cal_t cal;
static pour_motor_cal_config_t cfg;

void setUp(void) {
  const pour_motor_cal_config_t c = {20000u, 64000u, 64000u, 4000u, 1000u, 4096u, 9102u};
  cfg = c;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_motor_cal_init(&cal, &cfg, 100u));
}
void tearDown(void) {}

static void test_motor_cal_init_RefusesEachFieldOutOfRange(void) {
  pour_motor_cal_config_t bad[9];
  for (int k = 0; k < 9; ++k) bad[k] = cfg;
  bad[0].pwm_hz = 999u;
  bad[1].pwm_hz = 40001u;
  bad[2].i_base_ma = 0u;
  bad[3].v_base_mv = 100001u;
  bad[4].current_ma = 32001u; /* above half the current base */
  bad[5].l_test_mv = 99u;
  bad[6].encoder_cpr = 3000u; /* not a power of two */
  bad[7].encoder_cpr = 128u;
  bad[8].motion_counts = 4096u / 32u - 1u; /* less than an electrical turn of the finest motor */
  for (int k = 0; k < 9; ++k) TEST_ASSERT_EQUAL_INT_MESSAGE(POUR_EINVAL, pour_motor_cal_init(&cal, &bad[k], 0u), "case");
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_motor_cal_init(NULL, &cfg, 0u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_motor_cal_init(&cal, NULL, 0u));
}

static void test_motor_cal_NoCurrentAtTheBusLimitIsAnOpenCircuit(void) {
  q15_t va = 0, vb = 0;
  pour_motor_cal_status_t st = POUR_MOTOR_CAL_RUNNING;
  int32_t peak = 0;
  long n = 0;
  for (; n < 20000 && st == POUR_MOTOR_CAL_RUNNING; ++n) {
    st = pour_motor_cal_step(&cal, 0, 0, 100u, 6000, &va, &vb);
    if (va > peak) peak = va;
  }
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_RESISTANCE, st);
  TEST_ASSERT_EQUAL_INT32(6000, peak); /* the integrator stopped at the limit it was given */
  TEST_ASSERT_EQUAL_INT(8000, n);      /* the α axis's settling and measuring windows */
  TEST_ASSERT_EQUAL_INT(0, va);
  TEST_ASSERT_EQUAL_INT(0, vb);
}

static void test_motor_cal_AnEncoderBeyondTheRangeStopsItAtOnce(void) {
  q15_t va, vb;
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_RUNNING, pour_motor_cal_step(&cal, 0, 0, 100u, 6000, &va, &vb));
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_RUNNING, pour_motor_cal_step(&cal, 0, 0, 100u + 1000u, 6000, &va, &vb));
  /* backwards through the counter's wrap, beyond 9102 counts from the start in all */
  uint16_t enc = 100u + 1000u;
  pour_motor_cal_status_t st = POUR_MOTOR_CAL_RUNNING;
  for (int k = 0; k < 12 && st == POUR_MOTOR_CAL_RUNNING; ++k) {
    enc = (uint16_t)((enc + 4096u - 1000u) & 4095u);
    st = pour_motor_cal_step(&cal, 0, 0, enc, 6000, &va, &vb);
  }
  TEST_ASSERT_EQUAL_INT(POUR_MOTOR_CAL_MOTION, st);
  TEST_ASSERT_EQUAL_UINT32(10000u, cal.result.peak_counts);
  TEST_ASSERT_EQUAL_INT(0, va);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_motor_cal_init_RefusesEachFieldOutOfRange);
  RUN_TEST(test_motor_cal_NoCurrentAtTheBusLimitIsAnOpenCircuit);
  RUN_TEST(test_motor_cal_AnEncoderBeyondTheRangeStopsItAtOnce);
  return UNITY_END();
}
