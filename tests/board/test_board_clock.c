/* SPDX-License-Identifier: MIT */
/* The clock set-up against RCC, PWR, FLASH, LPTIM1 and SysTick register files in plain memory: HSI16 as the
 * reported fallback when the crystal does not start or cannot be timed, a PLL that never locks, the
 * crystal's frequency from its timing. A ready flag is "set by the hardware" by presetting it in the file;
 * the crystal timed and used is test_board_clock_timing.c's, where a thread plays the chip. */
#include <string.h>

#include "clock.h"
#include "stm32g431_regs.h"
#include "unity.h"

static uint32_t rcc[0x100 / 4], pwr[0x100 / 4], flash[0x100 / 4], lptim[0x40 / 4], systick[0x10 / 4];
static const pour_clock_hw_t hw = {rcc, pwr, flash, lptim, systick};
static pour_clock_config_t config;
static uint32_t hz, crystal;
static pour_clock_source_t source;

void setUp(void) {
  memset(rcc, 0, sizeof rcc);
  memset(pwr, 0, sizeof pwr);
  memset(flash, 0, sizeof flash);
  memset(lptim, 0, sizeof lptim);
  memset(systick, 0, sizeof systick);
  pwr[POUR_PWR_CR5] = POUR_MSK(PWR, CR5, R1MODE); /* reset value: range 1 normal */
  config = pour_clock_default_config();
  config.ready_polls = 10u;
  rcc[POUR_RCC_CFGR] = POUR_VAL(RCC, CFGR, SWS, 3u);
}

void tearDown(void) {}

static void test_clock_crystal_IsTheNearestMultipleOf4MHzWithin3Percent(void) {
  TEST_ASSERT_EQUAL_UINT32(24000000u, pour_clock_crystal_hz(24000000u));
  TEST_ASSERT_EQUAL_UINT32(24000000u, pour_clock_crystal_hz(23300000u)); /* HSI16 1 % slow, and more */
  TEST_ASSERT_EQUAL_UINT32(8000000u, pour_clock_crystal_hz(8230000u));
  TEST_ASSERT_EQUAL_UINT32(48000000u, pour_clock_crystal_hz(48000000u));
  TEST_ASSERT_EQUAL_UINT32(0u, pour_clock_crystal_hz(25000000u)); /* no integer M gives the PLL 4 MHz */
  TEST_ASSERT_EQUAL_UINT32(0u, pour_clock_crystal_hz(52000000u)); /* above the oscillator's 48 MHz */
  TEST_ASSERT_EQUAL_UINT32(0u, pour_clock_crystal_hz(1000000u));
  TEST_ASSERT_EQUAL_UINT32(0u, pour_clock_crystal_hz(0u));
}

static void test_clock_setup_FallsBackToHsi16AndSaysSo(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, PLLRDY); /* the crystal never becomes ready */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_UINT32(170000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(0u, crystal);
  TEST_ASSERT_EQUAL_UINT32(2u, POUR_GET(RCC, PLLCFGR, PLLSRC, rcc[POUR_RCC_PLLCFGR]));
  TEST_ASSERT_EQUAL_UINT32(3u, POUR_GET(RCC, PLLCFGR, PLLM, rcc[POUR_RCC_PLLCFGR])); /* 16 MHz / 4 */
  TEST_ASSERT_BITS_LOW(POUR_MSK(RCC, CR, HSEON) | POUR_MSK(RCC, CR, CSSON), rcc[POUR_RCC_CR]);
}

/* The crystal starts but cannot be timed (here: the core never switches to it, the counters never run):
 * an untimed crystal is not used. */
static void test_clock_setup_DoesNotUseACrystalItCouldNotTime(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY) | POUR_MSK(RCC, CR, PLLRDY);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(0u, crystal);
  TEST_ASSERT_EQUAL_UINT32(2u, POUR_GET(RCC, PLLCFGR, PLLSRC, rcc[POUR_RCC_PLLCFGR]));
  TEST_ASSERT_BITS_LOW(POUR_MSK(RCC, CR, HSEON) | POUR_MSK(RCC, CR, CSSON), rcc[POUR_RCC_CR]);
  TEST_ASSERT_BITS_LOW(POUR_MSK(RCC, APB1ENR1, LPTIM1EN), rcc[POUR_RCC_APB1ENR1]); /* timer off again */
  TEST_ASSERT_EQUAL_HEX32(0u, lptim[POUR_LPTIM_CR]);
  TEST_ASSERT_EQUAL_HEX32(0u, systick[POUR_SYST_CSR]);
}

static void test_clock_setup_StaysOnHsi16WhenThePllDoesNotLock(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY);
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_UINT32(16000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(1u, POUR_GET(RCC, CFGR, SW, rcc[POUR_RCC_CFGR])); /* HSI16, never the PLL */
  TEST_ASSERT_EQUAL_UINT32(0u, crystal); /* the PLL does not run from it */
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(RCC, CFGR, HPRE, rcc[POUR_RCC_CFGR])); /* AHB /1 again */
}

static void test_clock_setup_RefusesABadConfig(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY) | POUR_MSK(RCC, CR, PLLRDY);
  config.ready_polls = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_UINT32(16000000u, hz);
  TEST_ASSERT_EQUAL_HEX32(0u, rcc[POUR_RCC_PLLCFGR]); /* nothing touched */
  config = pour_clock_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(NULL, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source, NULL));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_clock_crystal_IsTheNearestMultipleOf4MHzWithin3Percent);
  RUN_TEST(test_clock_setup_FallsBackToHsi16AndSaysSo);
  RUN_TEST(test_clock_setup_DoesNotUseACrystalItCouldNotTime);
  RUN_TEST(test_clock_setup_StaysOnHsi16WhenThePllDoesNotLock);
  RUN_TEST(test_clock_setup_RefusesABadConfig);
  return UNITY_END();
}
