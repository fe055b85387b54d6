/* SPDX-License-Identifier: MIT */
/* The independent watchdog against a register file: the timeout programmed for the fastest LSI, so it is never
 * shorter than asked anywhere in the datasheet's 29.5 .. 34 kHz; the flash save's timeout covers the slowest
 * 2 KB page erase (24.47 ms) where the loop's 10 ms does not; a value that never settles, a bad timeout. */
#include <string.h>

#include "hal_watchdog.h"
#include "iwdg.h"
#include "pour/board_facts.h"
#include "stm32g431_regs.h"
#include "unity.h"

#define LSI_MIN_HZ 29500u

static uint32_t regs[4];

void setUp(void) { memset(regs, 0, sizeof regs); }

void tearDown(void) {}

static uint32_t shortest_us(void) {
  return pour_iwdg_timeout_us(regs[POUR_IWDG_PR], regs[POUR_IWDG_RLR], POUR_BOARD_LSI_MAX_HZ);
}

static void test_iwdg_set_IsNeverShorterThanAskedAtTheFastestLsi(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_iwdg_set(regs, POUR_WATCHDOG_TIMEOUT_MS, 10u));
  TEST_ASSERT_EQUAL_HEX32(0xAAAAu, regs[POUR_IWDG_KR]); /* reloaded last */
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_IWDG_PR]);      /* LSI / 4 */
  TEST_ASSERT_TRUE(shortest_us() >= POUR_WATCHDOG_TIMEOUT_MS * 1000u);
  TEST_ASSERT_TRUE(shortest_us() < POUR_WATCHDOG_TIMEOUT_MS * 1000u + 200u);
  const uint32_t longest = pour_iwdg_timeout_us(regs[POUR_IWDG_PR], regs[POUR_IWDG_RLR], LSI_MIN_HZ);
  TEST_ASSERT_TRUE(longest < 12000u); /* ten missed ticks, twelve at most on the slowest LSI */
}

static void test_iwdg_TheFlashSaveOutlastsTheSlowestPageEraseTheLoopsTimeoutDoesNot(void) {
  /* the loop's 10 ms: a page erase (up to 24.47 ms, the core stalled) would reset the board mid-save */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_iwdg_set(regs, POUR_WATCHDOG_TIMEOUT_MS, 10u));
  TEST_ASSERT_TRUE(shortest_us() < POUR_BOARD_FLASH_PAGE_ERASE_MAX_US);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_iwdg_set(regs, POUR_WATCHDOG_FLASH_MS, 10u));
  TEST_ASSERT_TRUE(shortest_us() > POUR_BOARD_FLASH_PAGE_ERASE_MAX_US + 1000u); /* and the loop's tick after it */
}

static void test_iwdg_set_RefusesWhatItCannotSet(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_iwdg_set(regs, 0u, 10u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_iwdg_set(regs, 500u, 10u)); /* beyond RLR's 4095 at LSI / 4 */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_iwdg_set(NULL, 10u, 10u));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_iwdg_set(regs, 480u, 10u));
  regs[POUR_IWDG_SR] = 2u; /* RVU stuck: the new reload never reaches the IWDG's domain */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_iwdg_set(regs, 10u, 10u));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_iwdg_set_IsNeverShorterThanAskedAtTheFastestLsi);
  RUN_TEST(test_iwdg_TheFlashSaveOutlastsTheSlowestPageEraseTheLoopsTimeoutDoesNot);
  RUN_TEST(test_iwdg_set_RefusesWhatItCannotSet);
  return UNITY_END();
}
