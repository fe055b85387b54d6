/* SPDX-License-Identifier: MIT */
/* The flash driver against a register file and a page in plain memory: unlock, page erase, double-word
 * programming, read-back, lock afterwards, and the failures: an error flag, a busy flag that never
 * clears, a page that is not blank after the erase, a lock that does not open. */
#include <string.h>

#include "flash_g4.h"
#include "flash_page_file.h"
#include "unity.h"

void setUp(void) {
  flash_page_file_reset();
}

void tearDown(void) {}

static const uint32_t w[4] = {1u, 2u, 3u, 4u};

static void test_flash_write_page_ProgramsReadsBackAndLocks(void) {
  page[100] = 0x0u; /* only the erase would clear it: plain memory keeps it, so erase reads not blank */
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_FAILED, pour_flash_write_page(&f, w, 4u));
  TEST_ASSERT_EQUAL_HEX32(1u << 31, regs[POUR_FLASH_CR]); /* locked even so */
  regs[POUR_FLASH_CR] = 0u;
  page[100] = 0xFFFFFFFFu;
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_OK, pour_flash_write_page(&f, w, 4u));
  TEST_ASSERT_EQUAL_HEX32_ARRAY(w, page, 4);
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, page[4]);
  TEST_ASSERT_EQUAL_HEX32(1u << 31, regs[POUR_FLASH_CR]); /* PG and PER off, locked */
}

static void test_flash_write_page_RefusesBadArguments(void) {
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_BAD_ARGS, pour_flash_write_page(&f, w, 3u));
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_BAD_ARGS, pour_flash_write_page(&f, w, POUR_FLASH_PAGE_BYTES / 4u + 2u));
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_BAD_ARGS, pour_flash_write_page(&f, NULL, 2u));
  f.page_number = 128u;
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_BAD_ARGS, pour_flash_write_page(&f, w, 2u));
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_FLASH_CR]); /* nothing touched */
}

static void test_flash_FailsOnAnErrorFlagOrABusyFlag(void) {
  regs[POUR_FLASH_SR] = 1u << 3; /* PROGERR that will not clear */
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_FAILED, pour_flash_write_page(&f, w, 2u));
  TEST_ASSERT_EQUAL_HEX32(1u << 31, regs[POUR_FLASH_CR]);
  regs[POUR_FLASH_SR] = 1u << 16; /* BSY forever */
  regs[POUR_FLASH_CR] = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_FAILED, pour_flash_write_page(&f, w, 2u));
}

static void test_flash_UnlocksWithTheKeysAndFailsIfItStaysLocked(void) {
  regs[POUR_FLASH_CR] = 1u << 31; /* locked, and plain memory never unlocks */
  TEST_ASSERT_EQUAL_INT(POUR_FLASH_FAILED, pour_flash_write_page(&f, w, 2u));
  TEST_ASSERT_EQUAL_HEX32(0xCDEF89ABu, regs[POUR_FLASH_KEYR]); /* the second key, after the first */
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, page[0]);               /* never programmed */
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_flash_write_page_ProgramsReadsBackAndLocks);
  RUN_TEST(test_flash_write_page_RefusesBadArguments);
  RUN_TEST(test_flash_FailsOnAnErrorFlagOrABusyFlag);
  RUN_TEST(test_flash_UnlocksWithTheKeysAndFailsIfItStaysLocked);
  return UNITY_END();
}
