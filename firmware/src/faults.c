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

/* Appends text at *at, keeping one byte for the terminator. */
static void append(char *buf, size_t size, size_t *at, const char *text) {
  while (*text != '\0' && *at + 1u < size) {
    buf[(*at)++] = *text++;
  }
  buf[*at] = '\0';
}

const char *pour_faults_format(uint16_t faults, char *buf, size_t size) {
  if (buf == NULL || size == 0u) {
    return buf;
  }
  size_t at = 0;
  buf[0] = '\0';
  if (faults == 0u) {
    append(buf, size, &at, "none");
    return buf;
  }
  for (unsigned i = 0; i < 16u; ++i) {
    const uint16_t bit = (uint16_t)(1u << i);
    if ((faults & bit) == 0u) {
      continue;
    }
    if (at > 0u) {
      append(buf, size, &at, ",");
    }
    const char *name = pour_fault_name(bit);
    if (name != NULL) {
      append(buf, size, &at, name);
    } else {
      const char digits[3] = {(char)('0' + i / 10u), (char)('0' + i % 10u), '\0'};
      append(buf, size, &at, "BIT");
      append(buf, size, &at, i < 10u ? digits + 1 : digits);
    }
  }
  return buf;
}

const char *pour_mode_name(uint8_t mode) { return mode < POUR_MODE_COUNT ? mode_names[mode] : NULL; }
