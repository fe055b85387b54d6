/* SPDX-License-Identifier: MIT */
/* hal_led: the board's LED showing the mode once per tick (the patterns: led.h). */
#ifndef POUR_HAL_LED_H
#define POUR_HAL_LED_H

#include <stdbool.h>
#include <stdint.h>

/* mode: pour_mode_t; refused: start-up failed and the controller will not run. */
void pour_hal_led_show(uint8_t mode, bool refused);

#endif /* POUR_HAL_LED_H */
