/* SPDX-License-Identifier: MIT */
#include "led.h"

#include "pour/control.h"

bool pour_led_pattern(uint8_t mode, bool refused, uint32_t tick) {
  if (refused) {
    return tick % 2000u < 100u;
  }
  const uint32_t t = tick % 1000u;
  switch (mode) {
  case POUR_MODE_RUN: return true;
  case POUR_MODE_FAULT: return t % 200u < 100u;
  case POUR_MODE_ESTOP: return t < 100u || (t >= 200u && t < 300u);
  default: return t < 500u; /* IDLE */
  }
}
