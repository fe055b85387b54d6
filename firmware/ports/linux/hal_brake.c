/* SPDX-License-Identifier: MIT */
/* hal_brake on Linux: the process drives no brake of its own (a bench's drive does, from the controller's
 * mode), so the line is kept and its engagements counted for the exit summary. */
#include "hal_brake.h"

#include "hal_lines.h"

static bool engaged = true;
static long engagements;

void pour_hal_brake_init(void) {
  engaged = true;
  engagements = 0;
}

void pour_hal_brake_set(bool engage) {
  if (engage && !engaged) {
    engagements++;
  }
  engaged = engage;
}

bool pour_hal_brake_engaged(void) { return engaged; }

long pour_hal_brake_engagements(void) { return engagements; }
