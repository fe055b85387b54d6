/* SPDX-License-Identifier: MIT */
#include "pour/faults.h"

#include <stddef.h>

/* Indexed by bit position: the one spelling of each fault that every tool prints. */
static const char *const fault_names[POUR_FAULT_COUNT] = {
    "STALE_INPUT", "ESTOP", "BAD_INPUT", "POSITION", "OVERSPEED", "TORQUE_SIGN",
    "ENCODER",     "VOLUME", "LINK",     "SEQ",      "SCALE",       "DRIVE",
};

static const char *const mode_names[POUR_MODE_COUNT] = {"IDLE", "RUN", "FAULT", "ESTOP"};

const char *pour_fault_name(uint16_t bit) {
  for (unsigned i = 0; i < POUR_FAULT_COUNT; ++i) {
    if (bit == (uint16_t)(1u << i)) {
      return fault_names[i];
    }
  }
  return NULL;
}

const char *pour_mode_name(uint8_t mode) { return mode < POUR_MODE_COUNT ? mode_names[mode] : NULL; }
