/* SPDX-License-Identifier: MIT */
/* The LED's patterns, one per mode, as docs/bringup.md lists them. */
#include "led.h"
#include "pour/control.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static unsigned on_ms(uint8_t mode, bool refused, uint32_t from, uint32_t to) {
  unsigned n = 0;
  for (uint32_t t = from; t < to; ++t) {
    n += pour_led_pattern(mode, refused, t) ? 1u : 0u;
  }
  return n;
}

static unsigned edges(uint8_t mode, bool refused, uint32_t to) {
  unsigned n = 0;
  for (uint32_t t = 1; t < to; ++t) {
    n += (pour_led_pattern(mode, refused, t) && !pour_led_pattern(mode, refused, t - 1u)) ? 1u : 0u;
  }
  return n;
}

static void test_led_EachModeHasItsOwnPattern(void) {
  TEST_ASSERT_EQUAL_UINT(2000u, on_ms(POUR_MODE_RUN, false, 0u, 2000u));
  TEST_ASSERT_EQUAL_UINT(1000u, on_ms(POUR_MODE_IDLE, false, 0u, 2000u));
  TEST_ASSERT_EQUAL_UINT(1u, edges(POUR_MODE_IDLE, false, 2000u));     /* 1 Hz (the first on is at t = 0) */
  TEST_ASSERT_EQUAL_UINT(9u, edges(POUR_MODE_FAULT, false, 2000u));    /* 5 Hz */
  TEST_ASSERT_EQUAL_UINT(3u, edges(POUR_MODE_ESTOP, false, 2000u));    /* two flashes a second */
  TEST_ASSERT_EQUAL_UINT(400u, on_ms(POUR_MODE_ESTOP, false, 0u, 2000u));
  TEST_ASSERT_EQUAL_UINT(200u, on_ms(POUR_MODE_RUN, true, 0u, 4000u)); /* refused wins over the mode */
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_led_EachModeHasItsOwnPattern);
  return UNITY_END();
}
