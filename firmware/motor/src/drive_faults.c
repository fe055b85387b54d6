/* SPDX-License-Identifier: MIT */
#include "pour/drive_faults.h"

#include <stddef.h>

/* Indexed by bit position (POUR_DRIVE_FAULT_*): the one spelling every tool prints. */
static const char *const drive_fault_names[POUR_DRIVE_FAULT_COUNT] = {
    "OVERCURRENT", "HW_OVERCURRENT",     "OVERVOLTAGE",       "UNDERVOLTAGE", "OVERTEMP", "CURRENT_OFFSET",
    "PHASE",       "ENCODER_DIRECTION", "ENCODER_MISMATCH", "CALIBRATION",  "I2T",
};

const char *pour_drive_fault_name(uint32_t bit) {
  for (unsigned i = 0; i < POUR_DRIVE_FAULT_COUNT; ++i) {
    if (bit == (1u << i)) {
      return drive_fault_names[i];
    }
  }
  return NULL;
}
