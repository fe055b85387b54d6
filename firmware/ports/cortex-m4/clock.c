/* SPDX-License-Identifier: MIT */
#include "clock.h"

#include <stddef.h>

#include "stm32g431_regs.h"

#define HSI16_HZ 16000000u
#define PLL_IN_HZ 4000000u /* VCO input: within 2.66 .. 8 MHz for any M */
#define PLL_N 85u          /* 4 MHz x 85 = 340 MHz VCO (96 .. 344 MHz) */
#define PLL_HZ 170000000u  /* VCO / R 2 */
#define PLLSRC_HSI16 2u
#define PLLSRC_HSE 3u
#define SW_PLL 3u
#define HPRE_DIV2 8u
#define FLASH_WAIT_STATES 4u /* 170 MHz in range 1 boost (RM0440 table 29) */

pour_clock_config_t pour_clock_default_config(void) {
  pour_clock_config_t c;
  c.hse_hz = 24000000u;
  c.ready_polls = 100000u;
  return c;
}

static void pll_from(volatile uint32_t *rcc, uint32_t src, uint32_t in_hz) {
  rcc[POUR_RCC_PLLCFGR] = POUR_VAL(RCC, PLLCFGR, PLLSRC, src) | POUR_VAL(RCC, PLLCFGR, PLLM, in_hz / PLL_IN_HZ - 1u) |
                          POUR_VAL(RCC, PLLCFGR, PLLN, PLL_N) | POUR_MSK(RCC, PLLCFGR, PLLREN) |
                          POUR_VAL(RCC, PLLCFGR, PLLR, 0u); /* R /2 */
}

pour_status_t pour_clock_setup(const pour_clock_hw_t *hw, const pour_clock_config_t *config, uint32_t *core_clock_hz,
                               pour_clock_source_t *source) {
  if (hw == NULL || config == NULL || core_clock_hz == NULL || source == NULL) {
    return POUR_EINVAL;
  }
  *core_clock_hz = HSI16_HZ;
  *source = POUR_CLOCK_HSI16;
  if (config->ready_polls == 0u || config->hse_hz % PLL_IN_HZ != 0u || config->hse_hz < PLL_IN_HZ ||
      config->hse_hz > 48000000u) {
    return POUR_EINVAL;
  }
  volatile uint32_t *const rcc = hw->rcc;
  const uint32_t polls = config->ready_polls;
  const uint32_t hpre = POUR_MSK(RCC, CFGR, HPRE);
  rcc[POUR_RCC_APB1ENR1] |= POUR_MSK(RCC, APB1ENR1, PWREN);
  (void)rcc[POUR_RCC_APB1ENR1];
  rcc[POUR_RCC_CFGR] = (rcc[POUR_RCC_CFGR] & ~hpre) | POUR_VAL(RCC, CFGR, HPRE, HPRE_DIV2); /* /2 into boost */
  hw->pwr[POUR_PWR_CR5] &= ~POUR_MSK(PWR, CR5, R1MODE); /* range 1 boost, up to 170 MHz */
  const uint32_t latency = POUR_VAL(FLASH, ACR, LATENCY, FLASH_WAIT_STATES);
  hw->flash[POUR_FLASH_ACR] = (hw->flash[POUR_FLASH_ACR] & ~POUR_MSK(FLASH, ACR, LATENCY)) | latency |
                              POUR_MSK(FLASH, ACR, PRFTEN) | POUR_MSK(FLASH, ACR, ICEN) | POUR_MSK(FLASH, ACR, DCEN);
  if (pour_regs_wait(&hw->flash[POUR_FLASH_ACR], POUR_MSK(FLASH, ACR, LATENCY), latency, polls) != 0) {
    return POUR_EINVAL;
  }
  /* The crystal first; the clock security system then watches it (a crystal that stops later hands the
   * core to HSI16 in hardware and raises the NMI, which startup.c turns into the safe outputs). */
  rcc[POUR_RCC_CR] = (rcc[POUR_RCC_CR] & ~POUR_MSK(RCC, CR, HSEBYP)) | POUR_MSK(RCC, CR, HSEON);
  const uint32_t hserdy = POUR_MSK(RCC, CR, HSERDY);
  if (pour_regs_wait(&rcc[POUR_RCC_CR], hserdy, hserdy, polls) == 0) {
    pll_from(rcc, PLLSRC_HSE, config->hse_hz);
    rcc[POUR_RCC_CR] |= POUR_MSK(RCC, CR, CSSON);
    *source = POUR_CLOCK_HSE;
  } else {
    rcc[POUR_RCC_CR] &= ~POUR_MSK(RCC, CR, HSEON);
    pll_from(rcc, PLLSRC_HSI16, HSI16_HZ);
  }
  rcc[POUR_RCC_CR] |= POUR_MSK(RCC, CR, PLLON);
  const uint32_t pllrdy = POUR_MSK(RCC, CR, PLLRDY);
  const uint32_t sws_pll = POUR_VAL(RCC, CFGR, SWS, SW_PLL);
  if (pour_regs_wait(&rcc[POUR_RCC_CR], pllrdy, pllrdy, polls) != 0) {
    rcc[POUR_RCC_CFGR] &= ~hpre;
    *source = POUR_CLOCK_HSI16;
    return POUR_EINVAL;
  }
  rcc[POUR_RCC_CFGR] = (rcc[POUR_RCC_CFGR] & ~POUR_MSK(RCC, CFGR, SW)) | POUR_VAL(RCC, CFGR, SW, SW_PLL);
  if (pour_regs_wait(&rcc[POUR_RCC_CFGR], POUR_MSK(RCC, CFGR, SWS), sws_pll, polls) != 0) {
    rcc[POUR_RCC_CFGR] &= ~hpre;
    *source = POUR_CLOCK_HSI16;
    return POUR_EINVAL;
  }
  for (volatile uint32_t i = 0; i < 200u; ++i) { /* >= 1 µs at 85 MHz before HPRE /1 (RM0440 §6.2.7) */
  }
  rcc[POUR_RCC_CFGR] &= ~(hpre | POUR_MSK(RCC, CFGR, PPRE1) | POUR_MSK(RCC, CFGR, PPRE2)); /* 170 MHz everywhere */
  *core_clock_hz = PLL_HZ;
  return POUR_OK;
}
