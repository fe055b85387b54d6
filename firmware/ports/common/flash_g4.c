/* SPDX-License-Identifier: MIT */
#include "flash_g4.h"

#include <stddef.h>

#define KEY1 0x45670123u
#define KEY2 0xCDEF89ABu
#define SR_ERRORS                                                                                             \
  (POUR_MSK(FLASH, SR, OPERR) | POUR_MSK(FLASH, SR, PROGERR) | POUR_MSK(FLASH, SR, WRPERR) |                  \
   POUR_MSK(FLASH, SR, PGAERR) | POUR_MSK(FLASH, SR, SIZERR) | POUR_MSK(FLASH, SR, PGSERR) |                  \
   POUR_MSK(FLASH, SR, MISERR) | POUR_MSK(FLASH, SR, FASTERR))

static int idle(const pour_flash_t *f) {
  return pour_regs_wait(&f->regs[POUR_FLASH_SR], POUR_MSK(FLASH, SR, BSY), 0u, f->busy_polls);
}

static int begin(const pour_flash_t *f) {
  if (idle(f) != 0) {
    return -1;
  }
  const uint32_t left = f->regs[POUR_FLASH_SR] & (SR_ERRORS | POUR_MSK(FLASH, SR, EOP));
  if (left != 0u) {
    f->regs[POUR_FLASH_SR] = left; /* write 1 to clear what an earlier operation left */
  }
  if ((f->regs[POUR_FLASH_CR] & POUR_MSK(FLASH, CR, LOCK)) != 0u) {
    f->regs[POUR_FLASH_KEYR] = KEY1;
    f->regs[POUR_FLASH_KEYR] = KEY2;
  }
  return (f->regs[POUR_FLASH_CR] & POUR_MSK(FLASH, CR, LOCK)) == 0u ? 0 : -1;
}

static int lock(const pour_flash_t *f, int result) {
  const int done = idle(f);
  const uint32_t errors = f->regs[POUR_FLASH_SR] & SR_ERRORS;
  f->regs[POUR_FLASH_CR] = POUR_MSK(FLASH, CR, LOCK); /* PG, PER off; locked */
  return result == 0 && done == 0 && errors == 0u ? 0 : -1;
}

static int erase(const pour_flash_t *f) {
  f->regs[POUR_FLASH_CR] = POUR_MSK(FLASH, CR, PER) | POUR_VAL(FLASH, CR, PNB, f->page_number);
  f->regs[POUR_FLASH_CR] |= POUR_MSK(FLASH, CR, STRT);
  if (idle(f) != 0 || (f->regs[POUR_FLASH_SR] & SR_ERRORS) != 0u) {
    return -1;
  }
  for (uint32_t i = 0; i < POUR_FLASH_PAGE_BYTES / 4u; ++i) {
    if (f->page[i] != 0xFFFFFFFFu) {
      return -1;
    }
  }
  return 0;
}

static int program(const pour_flash_t *f, const uint32_t *words, uint32_t n_words) {
  f->regs[POUR_FLASH_CR] = POUR_MSK(FLASH, CR, PG);
  for (uint32_t i = 0; i < n_words; i += 2u) {
    f->page[i] = words[i]; /* a double word: both halves, in order, then the interface programs it */
    f->page[i + 1u] = words[i + 1u];
    if (idle(f) != 0 || (f->regs[POUR_FLASH_SR] & SR_ERRORS) != 0u) {
      return -1;
    }
  }
  return 0;
}

int pour_flash_write_page(const pour_flash_t *f, const uint32_t *words, uint32_t n_words) {
  if (f == NULL || f->regs == NULL || f->page == NULL || f->busy_polls == 0u || f->page_number > 127u ||
      words == NULL || n_words % 2u != 0u || n_words > POUR_FLASH_PAGE_BYTES / 4u) {
    return POUR_FLASH_BAD_ARGS;
  }
  if (f->stall != NULL) {
    f->stall(true);
  }
  int result = begin(f);
  if (result == 0) {
    result = erase(f);
  }
  if (result == 0) {
    result = program(f, words, n_words);
  }
  result = lock(f, result) != 0 ? POUR_FLASH_FAILED : POUR_FLASH_OK;
  for (uint32_t i = 0; i < n_words && result == POUR_FLASH_OK; ++i) {
    if (f->page[i] != words[i]) {
      result = POUR_FLASH_FAILED;
    }
  }
  if (f->stall != NULL) {
    f->stall(false);
  }
  return result;
}
