/* SPDX-License-Identifier: MIT */
/* hal_power on Linux: no power stage of its own; the line is kept and its cuts counted for the summary. */
#include "hal_power.h"

#include "hal_lines.h"

static bool on;
static long cuts;

void pour_hal_power_init(void) {
  on = false;
  cuts = 0;
}

void pour_hal_power_set(bool enable) {
  if (!enable && on) {
    cuts++;
  }
  on = enable;
}

bool pour_hal_power_on(void) { return on; }

long pour_hal_power_cuts(void) { return cuts; }
