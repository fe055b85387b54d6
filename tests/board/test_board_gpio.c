/* SPDX-License-Identifier: MIT */
/* GPIO pins against a port's register file in plain memory: modes, pulls, alternate functions in AFRL and
 * AFRH, single-write set and reset through BSRR, and the other pins of the port left alone. */
#include <string.h>

#include "gpio.h"
#include "stm32g431_regs.h"
#include "unity.h"

static uint32_t port[0x400 / 4];

void setUp(void) {
  memset(port, 0, sizeof port);
  port[POUR_GPIO_MODER] = 0xFFFFFFFFu; /* reset: every pin analog */
}

void tearDown(void) {}

static void test_gpio_output_DrivesTheLevelThenTheMode(void) {
  const pour_gpio_t g = {port, 12u};
  port[POUR_GPIO_PUPDR] = 3u << 24;
  pour_gpio_output(g, false);
  TEST_ASSERT_EQUAL_HEX32(1u << (16u + 12u), port[POUR_GPIO_BSRR]); /* reset bit */
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu & ~(2u << 24), port[POUR_GPIO_MODER]); /* 01 for pin 12 only */
  TEST_ASSERT_EQUAL_HEX32(0u, port[POUR_GPIO_PUPDR]);
  pour_gpio_write(g, true);
  TEST_ASSERT_EQUAL_HEX32(1u << 12, port[POUR_GPIO_BSRR]);
}

static void test_gpio_input_SetsThePullAndInputMode(void) {
  const pour_gpio_t g = {port, 15u};
  pour_gpio_input(g, POUR_GPIO_PULL_DOWN);
  TEST_ASSERT_EQUAL_HEX32(0x3FFFFFFFu, port[POUR_GPIO_MODER]);
  TEST_ASSERT_EQUAL_HEX32(2u << 30, port[POUR_GPIO_PUPDR]);
  TEST_ASSERT_FALSE(pour_gpio_read(g));
  port[POUR_GPIO_IDR] = 1u << 15;
  TEST_ASSERT_TRUE(pour_gpio_read(g));
}

static void test_gpio_alternate_UsesAfrlBelowPin8AndAfrhFrom8(void) {
  const pour_gpio_t rx = {port, 11u};
  const pour_gpio_t enc = {port, 6u};
  pour_gpio_alternate(rx, 9u);
  pour_gpio_alternate(enc, 2u);
  TEST_ASSERT_EQUAL_HEX32(9u << 12, port[POUR_GPIO_AFRH]);
  TEST_ASSERT_EQUAL_HEX32(2u << 24, port[POUR_GPIO_AFRL]);
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu & ~(1u << 22) & ~(1u << 12), port[POUR_GPIO_MODER]); /* 10 for both */
}

static void test_gpio_speed_SetsOnlyThatPinsSpeed(void) {
  port[POUR_GPIO_OSPEEDR] = 0x0C000000u; /* port A's reset value: PA13 very high */
  pour_gpio_speed((pour_gpio_t){port, 8u}, POUR_GPIO_SPEED_HIGH);
  pour_gpio_speed((pour_gpio_t){port, 15u}, POUR_GPIO_SPEED_HIGH);
  TEST_ASSERT_EQUAL_HEX32(0x0C000000u | (2u << 16) | (2u << 30), port[POUR_GPIO_OSPEEDR]);
  pour_gpio_speed((pour_gpio_t){port, 15u}, POUR_GPIO_SPEED_LOW);
  TEST_ASSERT_EQUAL_HEX32(0x0C000000u | (2u << 16), port[POUR_GPIO_OSPEEDR]);
}

static void test_gpio_driven_ReadsTheOutputLatch(void) {
  const pour_gpio_t g = {port, 8u};
  TEST_ASSERT_FALSE(pour_gpio_driven(g));
  port[POUR_GPIO_ODR] = 1u << 8;
  TEST_ASSERT_TRUE(pour_gpio_driven(g));
  pour_gpio_analog(g);
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, port[POUR_GPIO_MODER]);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_gpio_output_DrivesTheLevelThenTheMode);
  RUN_TEST(test_gpio_input_SetsThePullAndInputMode);
  RUN_TEST(test_gpio_alternate_UsesAfrlBelowPin8AndAfrhFrom8);
  RUN_TEST(test_gpio_speed_SetsOnlyThatPinsSpeed);
  RUN_TEST(test_gpio_driven_ReadsTheOutputLatch);
  return UNITY_END();
}
