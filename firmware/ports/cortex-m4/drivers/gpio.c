/* SPDX-License-Identifier: MIT */
#include "gpio.h"

#include "stm32g431_regs.h"

static void set_field(volatile uint32_t *reg, uint32_t shift, uint32_t width, uint32_t value) {
  const uint32_t mask = (0xFFFFFFFFu >> (32u - width)) << shift;
  *reg = (*reg & ~mask) | ((value << shift) & mask);
}

static void mode(pour_gpio_t g, uint32_t m) {
  set_field(&g.port[POUR_GPIO_MODER], (uint32_t)POUR_GPIO_MODER_MODER0_WIDTH * g.pin,
            (uint32_t)POUR_GPIO_MODER_MODER0_WIDTH, m);
}

static void pull(pour_gpio_t g, uint32_t p) {
  set_field(&g.port[POUR_GPIO_PUPDR], (uint32_t)POUR_GPIO_PUPDR_PUPDR0_WIDTH * g.pin,
            (uint32_t)POUR_GPIO_PUPDR_PUPDR0_WIDTH, p);
}

void pour_gpio_write(pour_gpio_t g, bool level) {
  /* BSRR: one write, no read-modify-write that an interrupt could tear. */
  g.port[POUR_GPIO_BSRR] = level ? POUR_MSK(GPIO, BSRR, BS0) << g.pin : POUR_MSK(GPIO, BSRR, BR0) << g.pin;
}

void pour_gpio_output(pour_gpio_t g, bool level) {
  pour_gpio_write(g, level);
  g.port[POUR_GPIO_OTYPER] &= ~(POUR_MSK(GPIO, OTYPER, OT0) << g.pin);
  pull(g, POUR_GPIO_PULL_NONE);
  mode(g, POUR_GPIO_MODE_OUTPUT);
}

void pour_gpio_input(pour_gpio_t g, uint32_t p) {
  pull(g, p);
  mode(g, POUR_GPIO_MODE_INPUT);
}

void pour_gpio_alternate(pour_gpio_t g, uint32_t af) {
  const uint32_t w = (uint32_t)POUR_GPIO_AFRL_AFRL0_WIDTH;
  if (g.pin < 8u) {
    set_field(&g.port[POUR_GPIO_AFRL], w * g.pin, w, af);
  } else {
    set_field(&g.port[POUR_GPIO_AFRH], w * (g.pin - 8u), w, af);
  }
  pull(g, POUR_GPIO_PULL_NONE);
  mode(g, POUR_GPIO_MODE_AF);
}

void pour_gpio_speed(pour_gpio_t g, uint32_t speed) {
  set_field(&g.port[POUR_GPIO_OSPEEDR], (uint32_t)POUR_GPIO_OSPEEDR_OSPEEDR0_WIDTH * g.pin,
            (uint32_t)POUR_GPIO_OSPEEDR_OSPEEDR0_WIDTH, speed);
}

void pour_gpio_analog(pour_gpio_t g) {
  pull(g, POUR_GPIO_PULL_NONE);
  mode(g, POUR_GPIO_MODE_ANALOG);
}

bool pour_gpio_read(pour_gpio_t g) { return (g.port[POUR_GPIO_IDR] & (POUR_MSK(GPIO, IDR, IDR0) << g.pin)) != 0u; }

bool pour_gpio_driven(pour_gpio_t g) { return (g.port[POUR_GPIO_ODR] & (POUR_MSK(GPIO, ODR, ODR0) << g.pin)) != 0u; }
