/* SPDX-License-Identifier: MIT */
/* For the sim tests: a whole small file as a NUL-terminated text (a test failure if it cannot be opened). */
#ifndef POUR_TESTS_SIM_READ_TEXT_H
#define POUR_TESTS_SIM_READ_TEXT_H

#include <stdio.h>

#include "unity.h"

/* Reads at most cap - 1 bytes of path into buf and terminates them; returns how many. */
static inline size_t read_text(const char *path, char *buf, size_t cap) {
  FILE *f = fopen(path, "rb");
  TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
  size_t n = fread(buf, 1, cap - 1, f);
  fclose(f);
  buf[n] = '\0';
  return n;
}

#endif /* POUR_TESTS_SIM_READ_TEXT_H */
