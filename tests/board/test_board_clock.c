/* SPDX-License-Identifier: MIT */
/* The clock set-up against RCC, PWR and FLASH register files in plain memory: the crystal through the PLL
 * to 170 MHz, HSI16 as the reported fallback when the crystal does not start, a PLL that never locks. A
 * ready flag is "set by the hardware" by presetting it in the file. */
#include <string.h>

#include "clock.h"
#include "stm32g431_regs.h"
#include "unity.h"

static uint32_t rcc[0x100 / 4], pwr[0x100 / 4], flash[0x100 / 4];
static const pour_clock_hw_t hw = {rcc, pwr, flash};
static pour_clock_config_t config;
static uint32_t hz;
static pour_clock_source_t source;

void setUp(void) {
  memset(rcc, 0, sizeof rcc);
  memset(pwr, 0, sizeof pwr);
  memset(flash, 0, sizeof flash);
  pwr[POUR_PWR_CR5] = POUR_MSK(PWR, CR5, R1MODE); /* reset value: range 1 normal */
  config = pour_clock_default_config();
  config.ready_polls = 10u;
  rcc[POUR_RCC_CFGR] = POUR_VAL(RCC, CFGR, SWS, 3u);
}

void tearDown(void) {}

static void test_clock_setup_RunsThePllFromTheCrystalAt170MHz(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY) | POUR_MSK(RCC, CR, PLLRDY);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_clock_setup(&hw, &config, &hz, &source));
  TEST_ASSERT_EQUAL_UINT32(170000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSE, source);
  /* 24 MHz / M 6 = 4 MHz, x N 85 = 340 MHz, / R 2 */
  TEST_ASSERT_EQUAL_HEX32(POUR_VAL(RCC, PLLCFGR, PLLSRC, 3u) | POUR_VAL(RCC, PLLCFGR, PLLM, 5u) |
                              POUR_VAL(RCC, PLLCFGR, PLLN, 85u) | POUR_MSK(RCC, PLLCFGR, PLLREN),
                          rcc[POUR_RCC_PLLCFGR]);
  TEST_ASSERT_BITS_HIGH(POUR_MSK(RCC, CR, HSEON) | POUR_MSK(RCC, CR, CSSON) | POUR_MSK(RCC, CR, PLLON),
                        rcc[POUR_RCC_CR]);
  TEST_ASSERT_EQUAL_UINT32(3u, POUR_GET(RCC, CFGR, SW, rcc[POUR_RCC_CFGR]));
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(RCC, CFGR, HPRE, rcc[POUR_RCC_CFGR]));
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(PWR, CR5, R1MODE, pwr[POUR_PWR_CR5])); /* boost */
  TEST_ASSERT_EQUAL_UINT32(4u, POUR_GET(FLASH, ACR, LATENCY, flash[POUR_FLASH_ACR]));
  TEST_ASSERT_BITS_HIGH(POUR_MSK(RCC, APB1ENR1, PWREN), rcc[POUR_RCC_APB1ENR1]);
}

static void test_clock_setup_FallsBackToHsi16AndSaysSo(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, PLLRDY); /* the crystal never becomes ready */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_clock_setup(&hw, &config, &hz, &source));
  TEST_ASSERT_EQUAL_UINT32(170000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(2u, POUR_GET(RCC, PLLCFGR, PLLSRC, rcc[POUR_RCC_PLLCFGR]));
  TEST_ASSERT_EQUAL_UINT32(3u, POUR_GET(RCC, PLLCFGR, PLLM, rcc[POUR_RCC_PLLCFGR])); /* 16 MHz / 4 */
  TEST_ASSERT_BITS_LOW(POUR_MSK(RCC, CR, HSEON) | POUR_MSK(RCC, CR, CSSON), rcc[POUR_RCC_CR]);
}

static void test_clock_setup_StaysOnHsi16WhenThePllDoesNotLock(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY);
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source));
  TEST_ASSERT_EQUAL_UINT32(16000000u, hz);
  TEST_ASSERT_EQUAL_INT(POUR_CLOCK_HSI16, source);
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(RCC, CFGR, SW, rcc[POUR_RCC_CFGR])); /* never switched */
  TEST_ASSERT_EQUAL_UINT32(0u, POUR_GET(RCC, CFGR, HPRE, rcc[POUR_RCC_CFGR])); /* AHB /1 again */
}

static void test_clock_setup_RefusesABadConfig(void) {
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY) | POUR_MSK(RCC, CR, PLLRDY);
  config.hse_hz = 25000000u; /* no integer M gives a 4 MHz VCO input */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source));
  TEST_ASSERT_EQUAL_UINT32(16000000u, hz);
  TEST_ASSERT_EQUAL_HEX32(0u, rcc[POUR_RCC_PLLCFGR]); /* nothing touched */
  config = pour_clock_default_config();
  config.ready_polls = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(&hw, &config, &hz, &source));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_clock_setup(NULL, &config, &hz, &source));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_clock_setup_RunsThePllFromTheCrystalAt170MHz);
  RUN_TEST(test_clock_setup_FallsBackToHsi16AndSaysSo);
  RUN_TEST(test_clock_setup_StaysOnHsi16WhenThePllDoesNotLock);
  RUN_TEST(test_clock_setup_RefusesABadConfig);
  return UNITY_END();
}
