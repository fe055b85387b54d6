/* SPDX-License-Identifier: MIT */
/* The option bytes' boot check: only nSWBOOT0 = 0 with nBOOT0 = 1 boots main flash whatever PB8 (BOOT0, the
 * board's pull-up, the e-stop line) reads; the chip's factory value and every other combination are
 * refused by name. */
#include "boot_check.h"
#include "unity.h"

#define FACTORY 0xFFEFF8AAu /* RM0440's FLASH_OPTR factory value */
#define N_SWBOOT0 (1u << 26)
#define N_BOOT0 (1u << 27)
#define N_BOOT1 (1u << 23)

void setUp(void) {}

void tearDown(void) {}

static void test_boot_check_TheFactoryValueLetsThePinChooseAndIsRefused(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EBOOT, pour_boot_check_optr(FACTORY));
  TEST_ASSERT_EQUAL_STRING("POUR_EBOOT", pour_status_name(pour_boot_check_optr(FACTORY)));
}

static void test_boot_check_TheBitChoosingMainFlashPasses(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_boot_check_optr(FACTORY & ~N_SWBOOT0));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_boot_check_optr((FACTORY & ~N_SWBOOT0) & ~N_BOOT1)); /* nBOOT1 then moot */
}

static void test_boot_check_TheBitChoosingTheBootloaderIsRefused(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EBOOT, pour_boot_check_optr(FACTORY & ~N_SWBOOT0 & ~N_BOOT0));
  TEST_ASSERT_EQUAL_INT(POUR_EBOOT, pour_boot_check_optr(0u));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_boot_check_TheFactoryValueLetsThePinChooseAndIsRefused);
  RUN_TEST(test_boot_check_TheBitChoosingMainFlashPasses);
  RUN_TEST(test_boot_check_TheBitChoosingTheBootloaderIsRefused);
  return UNITY_END();
}
