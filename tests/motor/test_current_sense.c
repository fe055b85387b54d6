/* SPDX-License-Identifier: MIT */
#include "pour/board_facts.h"
#include "pour/current_sense.h"
#include "unity.h"

static pour_current_sense_t cs;
static const pour_current_sense_config_t cfg = {986000, 2048, 160};

void setUp(void) { TEST_ASSERT_EQUAL_INT(POUR_OK, pour_current_sense_init(&cs, &cfg)); }
void tearDown(void) {}

static int calibrate_with(uint16_t a, uint16_t b, uint16_t c) {
  int r = 0;
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) {
    const uint16_t adc[3] = {(uint16_t)(a + (n & 3)), b, c}; /* ±2 counts of noise on a: mean a + 1.5 */
    r = pour_current_sense_calibrate(&cs, adc);
    if (n < POUR_CURRENT_SENSE_CAL_SAMPLES - 1) TEST_ASSERT_EQUAL_INT(0, r);
  }
  return r;
}

static void test_current_sense_AcceptsOffsetsNearTheBias(void) {
  TEST_ASSERT_EQUAL_INT(1, calibrate_with(2040, 2100, 1990));
  TEST_ASSERT_EQUAL_UINT16(2042, cs.offset[0]); /* 2041.5 rounds up */
  TEST_ASSERT_EQUAL_UINT16(2100, cs.offset[1]);
  TEST_ASSERT_EQUAL_UINT16(1990, cs.offset[2]);
}

static void test_current_sense_RefusesAnOffsetOutOfRange(void) {
  TEST_ASSERT_EQUAL_INT(-1, calibrate_with(2048, 2048, 2048 + 161)); /* a broken amplifier on c */
  TEST_ASSERT_EQUAL_UINT8(0, cs.calibrated);
  setUp();
  TEST_ASSERT_EQUAL_INT(-1, calibrate_with(0, 2048, 2048)); /* an amplifier stuck at 0 */
}

static void test_current_sense_ConvertsThroughGainAndOffset(void) {
  TEST_ASSERT_EQUAL_INT(1, calibrate_with(2046, 2048, 2048));
  const uint16_t adc[3] = {2048 + 100, 2048, 2048 - 2048};
  q15_t i[3];
  pour_current_sense_convert(&cs, adc, i);
  /* 100 counts · 986000/65536 = 1504.5 LSB (2.94 A), of the board's sign: a count above the offset is current
   * out of the motor (pour/board_facts.h) */
  TEST_ASSERT_EQUAL_INT(-1, POUR_BOARD_CURRENT_SIGN);
  TEST_ASSERT_EQUAL_INT16(-1505, i[0]);
  TEST_ASSERT_EQUAL_INT16(0, i[1]);
  TEST_ASSERT_EQUAL_INT16(30813, i[2]); /* +30812.5, rounded up */
}

static void test_current_sense_SaturatesInsteadOfWrapping(void) {
  const pour_current_sense_config_t big = {4000000, 2048, 160};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_current_sense_init(&cs, &big));
  TEST_ASSERT_EQUAL_INT(1, calibrate_with(2048, 2048, 2048));
  const uint16_t adc[3] = {4095, 0, 2048};
  q15_t i[3];
  pour_current_sense_convert(&cs, adc, i);
  TEST_ASSERT_EQUAL_INT16(-32768, i[0]);
  TEST_ASSERT_EQUAL_INT16(32767, i[1]);
}

static void test_current_sense_InitRefusesBadConfig(void) {
  const pour_current_sense_config_t zero_gain = {0, 2048, 160};
  const pour_current_sense_config_t bad_bias = {986000, 5000, 160};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_current_sense_init(&cs, &zero_gain));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_current_sense_init(&cs, &bad_bias));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_current_sense_AcceptsOffsetsNearTheBias);
  RUN_TEST(test_current_sense_RefusesAnOffsetOutOfRange);
  RUN_TEST(test_current_sense_ConvertsThroughGainAndOffset);
  RUN_TEST(test_current_sense_SaturatesInsteadOfWrapping);
  RUN_TEST(test_current_sense_InitRefusesBadConfig);
  return UNITY_END();
}
