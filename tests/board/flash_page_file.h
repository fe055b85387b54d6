/* SPDX-License-Identifier: MIT */
/* The flash interface's register file and one erased page in plain memory, for the flash and calibration
 * tests (each test file gets its own copy). */
#ifndef POUR_FLASH_PAGE_FILE_H
#define POUR_FLASH_PAGE_FILE_H

#include <string.h>

#include "flash_g4.h"

static uint32_t regs[POUR_FLASH_N_REGS];
static uint32_t page[POUR_FLASH_PAGE_BYTES / 4];
static pour_flash_t f;

/* Registers cleared (unlocked, idle, no error), the page erased, f pointing at both. */
static void flash_page_file_reset(void) {
  memset(regs, 0, sizeof regs);
  memset(page, 0xFF, sizeof page);
  f.regs = regs;
  f.page = page;
  f.page_number = POUR_FLASH_CAL_PAGE;
  f.busy_polls = 10u;
  f.stall = NULL;
}

#endif /* POUR_FLASH_PAGE_FILE_H */
