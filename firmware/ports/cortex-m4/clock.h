/* SPDX-License-Identifier: MIT */
/* The core clock: the STM32G431 at 170 MHz from HSI16 through the PLL (RM0440 §6, §7). */
#ifndef POUR_CLOCK_H
#define POUR_CLOCK_H

#include <stdint.h>

#include "pour/fixed.h"

/* Switches the core to its running clock; *core_clock_hz gets it [Hz] (also the APB1 clock that feeds
 * FDCAN). POUR_EINVAL if the PLL does not lock (the core then stays on HSI16, which *core_clock_hz tells). */
pour_status_t pour_clock_init(uint32_t *core_clock_hz);

#endif /* POUR_CLOCK_H */
