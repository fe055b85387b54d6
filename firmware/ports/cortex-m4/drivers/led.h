/* SPDX-License-Identifier: MIT */
/* The board's LED (PC6) says the controller's mode without a bus analyser (docs/bringup.md):
 *   RUN    on
 *   IDLE   1 Hz, half on (ready, brake engaged)
 *   FAULT  5 Hz (a latched fault: read the heartbeat, then ClearErrors)
 *   ESTOP  two short flashes a second
 *   start-up refused (no policy, no clock, no calibration): on 100 ms every 2 s */
#ifndef POUR_LED_H
#define POUR_LED_H

#include <stdbool.h>
#include <stdint.h>

/* Whether the LED is on at tick [ms] in mode (pour_mode_t); refused: the controller will not run at all. */
bool pour_led_pattern(uint8_t mode, bool refused, uint32_t tick);

#endif /* POUR_LED_H */
