/* SPDX-License-Identifier: MIT */
/* The crystal timed against HSI16 and used, against register files a second thread keeps moving as the chip
 * would (clock_chip.h). Host only: a POSIX thread plays the chip. */
#define _POSIX_C_SOURCE 200112L /* clock_gettime under -std=c99 */
#include <pthread.h>
#include <string.h>

#include "clock.h"
#include "clock_chip.h"
#include "stm32g431_regs.h"
#include "unity.h"

static volatile uint32_t rcc[0x100 / 4], pwr[0x100 / 4], flash[0x100 / 4], lptim[0x40 / 4], systick[0x10 / 4];
static const pour_clock_hw_t hw = {rcc, pwr, flash, lptim, systick};
static volatile int running; /* the test's flag to the chip thread (set before it starts, cleared to end it) */
static clock_chip_t chip_state = {rcc, lptim, systick, 0u, 0u, 0u, 0u, 0u};

static void *chip(void *arg) {
  (void)arg;
  clock_chip_start(&chip_state);
  while (running) {
    clock_chip_step(&chip_state);
  }
  return NULL;
}

static pthread_t thread;
static pour_clock_config_t config;
static uint32_t hz, crystal;
static pour_clock_source_t source;

static void start_chip(uint32_t mhz_x10) {
  chip_state.crystal_mhz_x10 = mhz_x10;
  running = 1;
  TEST_ASSERT_EQUAL_INT(0, pthread_create(&thread, NULL, chip, NULL));
}

void setUp(void) {
  memset((void *)rcc, 0, sizeof rcc);
  memset((void *)pwr, 0, sizeof pwr);
  memset((void *)flash, 0, sizeof flash);
  memset((void *)lptim, 0, sizeof lptim);
  memset((void *)systick, 0, sizeof systick);
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY) | POUR_MSK(RCC, CR, PLLRDY);
  rcc[POUR_RCC_CFGR] = POUR_VAL(RCC, CFGR, SW, 1u) | POUR_VAL(RCC, CFGR, SWS, 1u); /* reset: HSI16 */
  config = pour_clock_default_config();
  config.ready_polls = 500000000u; /* the timing takes 80 ms of the host's time: polls enough for it */
}

void tearDown(void) {
  running = 0;
  pthread_join(thread, NULL);
}

static void expect_crystal_pll(uint32_t crystal_hz) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_UINT32(170000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSE, source);
  TEST_ASSERT_EQUAL_UINT32(crystal_hz, crystal);
  /* crystal / M = 4 MHz, x N 85 = 340 MHz, / R 2 */
  TEST_ASSERT_EQUAL_HEX32(POUR_VAL(RCC, PLLCFGR, PLLSRC, 3u) | POUR_VAL(RCC, PLLCFGR, PLLM, crystal_hz / 4000000u - 1u) |
                              POUR_VAL(RCC, PLLCFGR, PLLN, 85u) | POUR_MSK(RCC, PLLCFGR, PLLREN),
                          rcc[POUR_RCC_PLLCFGR]);
  TEST_ASSERT_BITS_HIGH(POUR_MSK(RCC, CR, HSEON) | POUR_MSK(RCC, CR, CSSON) | POUR_MSK(RCC, CR, PLLON),
                        rcc[POUR_RCC_CR]);
  TEST_ASSERT_EQUAL_UINT32(3u, POUR_GET(RCC, CFGR, SW, rcc[POUR_RCC_CFGR]));
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(RCC, CFGR, HPRE, rcc[POUR_RCC_CFGR]));
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(PWR, CR5, R1MODE, pwr[POUR_PWR_CR5])); /* boost */
  TEST_ASSERT_EQUAL_UINT32(4u, POUR_GET(FLASH, ACR, LATENCY, flash[POUR_FLASH_ACR]));
  TEST_ASSERT_EQUAL_UINT32(2u, POUR_GET(RCC, CCIPR, LPTIM1SEL, rcc[POUR_RCC_CCIPR])); /* timed against HSI16 */
  TEST_ASSERT_BITS_LOW(POUR_MSK(RCC, APB1ENR1, LPTIM1EN), rcc[POUR_RCC_APB1ENR1]);  /* and off again */
  TEST_ASSERT_EQUAL_HEX32(0u, lptim[POUR_LPTIM_CR]);
  TEST_ASSERT_EQUAL_HEX32(0u, systick[POUR_SYST_CSR]);
}

static void test_clock_timing_Finds24MHz(void) {
  start_chip(240u);
  expect_crystal_pll(24000000u);
}

static void test_clock_timing_Finds8MHz(void) {
  start_chip(80u);
  expect_crystal_pll(8000000u);
}

/* HSI16 1 % fast makes a 24 MHz crystal time at 23.76 MHz: still 24. */
static void test_clock_timing_ToleratesHsi16sError(void) {
  start_chip(238u);
  expect_crystal_pll(24000000u);
}

/* A 25 MHz crystal (the frequency of many other boards) cannot give the PLL its 4 MHz: HSI16, and said. */
static void test_clock_timing_RefusesA25MHzCrystal(void) {
  start_chip(250u);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_UINT32(170000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(0u, crystal);
  TEST_ASSERT_EQUAL_UINT32(2u, POUR_GET(RCC, PLLCFGR, PLLSRC, rcc[POUR_RCC_PLLCFGR]));
  TEST_ASSERT_BITS_LOW(POUR_MSK(RCC, CR, HSEON) | POUR_MSK(RCC, CR, CSSON), rcc[POUR_RCC_CR]);
}

/* The crystal timed, but the PLL never locks: the core stays on HSI16, and no crystal is reported in use. */
static void test_clock_timing_APllThatDoesNotLockReportsNoCrystal(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY);
  start_chip(240u);
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source, &crystal));
  TEST_ASSERT_EQUAL_UINT32(16000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(0u, crystal);
  TEST_ASSERT_EQUAL_UINT32(3u, POUR_GET(RCC, PLLCFGR, PLLSRC, rcc[POUR_RCC_PLLCFGR])); /* it was the crystal's */
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_clock_timing_Finds24MHz);
  RUN_TEST(test_clock_timing_Finds8MHz);
  RUN_TEST(test_clock_timing_ToleratesHsi16sError);
  RUN_TEST(test_clock_timing_RefusesA25MHzCrystal);
  RUN_TEST(test_clock_timing_APllThatDoesNotLockReportsNoCrystal);
  return UNITY_END();
}
