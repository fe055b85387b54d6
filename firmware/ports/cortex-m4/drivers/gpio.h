/* SPDX-License-Identifier: MIT */
/* GPIO pins of the STM32G431 by register (stm32g431_regs.h's GPIO table). A pin is its port's registers
 * and a number, so the same code runs on the chip and against a register file in a host test. */
#ifndef POUR_GPIO_H
#define POUR_GPIO_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
  volatile uint32_t *port; /* the port's registers (GPIOA, GPIOB, GPIOC on the chip) */
  uint8_t pin;             /* 0 .. 15 */
} pour_gpio_t;

/* Push-pull output, driven to level before it leaves the reset mode (no glitch to the other level). */
void pour_gpio_output(pour_gpio_t g, bool level);

/* Input with pull (POUR_GPIO_PULL_*). */
void pour_gpio_input(pour_gpio_t g, uint32_t pull);

/* Alternate function af (0 .. 15), no pull. */
void pour_gpio_alternate(pour_gpio_t g, uint32_t af);

/* Output speed (POUR_GPIO_SPEED_*): the edge rate of an output or an alternate function's output. */
void pour_gpio_speed(pour_gpio_t g, uint32_t speed);

/* Analog (ADC, OPAMP and comparator inputs), no pull. */
void pour_gpio_analog(pour_gpio_t g);

void pour_gpio_write(pour_gpio_t g, bool level);

/* The pin's input level. */
bool pour_gpio_read(pour_gpio_t g);

/* The level the output latch drives. */
bool pour_gpio_driven(pour_gpio_t g);

#endif /* POUR_GPIO_H */
