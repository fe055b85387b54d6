/* SPDX-License-Identifier: MIT */
/* The STM32G431's flash as the calibration's storage: page erase and double-word programming through the
 * flash interface's registers (RM0440 §5.3), each operation bounded, checked for the interface's error
 * flags and read back. Registers and the page through pointers: a register file and a page in plain
 * memory in tests/board/test_board_flash.c. */
#ifndef POUR_FLASH_G4_H
#define POUR_FLASH_G4_H

#include <stdbool.h>
#include <stdint.h>

#include "regs.h"

#define POUR_FLASH_PERIPHS(P) P(FLASH_IF, FLASH, 0x40022000)
#define POUR_FLASH_REGS(R) R(FLASH, KEYR, 0x08) R(FLASH, SR, 0x10) R(FLASH, CR, 0x14)
#define POUR_FLASH_FIELDS(F)                                                                                   \
  F(FLASH, SR, EOP, 0, 1)                                                                                      \
  F(FLASH, SR, OPERR, 1, 1)                                                                                    \
  F(FLASH, SR, PROGERR, 3, 1)                                                                                  \
  F(FLASH, SR, WRPERR, 4, 1)                                                                                   \
  F(FLASH, SR, PGAERR, 5, 1)                                                                                   \
  F(FLASH, SR, SIZERR, 6, 1)                                                                                   \
  F(FLASH, SR, PGSERR, 7, 1)                                                                                   \
  F(FLASH, SR, MISERR, 8, 1)                                                                                   \
  F(FLASH, SR, FASTERR, 9, 1)                                                                                  \
  F(FLASH, SR, BSY, 16, 1)                                                                                     \
  F(FLASH, CR, PG, 0, 1)                                                                                       \
  F(FLASH, CR, PER, 1, 1)                                                                                      \
  F(FLASH, CR, PNB, 3, 7)                                                                                      \
  F(FLASH, CR, STRT, 16, 1)                                                                                    \
  F(FLASH, CR, LOCK, 31, 1)
POUR_REGS_DECLARE(FLASH);
#define POUR_FLASH_N_REGS (0x80 / 4)
#define POUR_FLASH_PAGE_BYTES 2048u
#define POUR_FLASH_CAL_PAGE 63u            /* the last page of the 128 KB (the linker script leaves it) */
#define POUR_FLASH_CAL_ADDR 0x0801F800u

typedef struct {
  volatile uint32_t *regs;
  volatile uint32_t *page;   /* the page's first word (erase and program target) */
  uint32_t page_number;      /* PNB of that page */
  uint32_t busy_polls;       /* bound of each wait for BSY, > 0 */
  /* Called with true before the erase and false after the read-back, or NULL: the single-bank G431 stalls
   * every fetch for up to 24.5 ms of erase, so the board stretches its watchdog across it (hal_watchdog.h). */
  void (*stall)(bool begin);
} pour_flash_t;

/* Results of an erase or a program. */
#define POUR_FLASH_OK 0
#define POUR_FLASH_FAILED (-1) /* an error flag, a busy flag that never clears, or a read-back that differs */
#define POUR_FLASH_BAD_ARGS (-2)

/* Replaces the page's content: unlock, erase (checked blank), program n_words (even: double words, at
 * most a page) from words, lock, read back; f->stall (if any) around it all. */
int pour_flash_write_page(const pour_flash_t *f, const uint32_t *words, uint32_t n_words);

#endif /* POUR_FLASH_G4_H */
