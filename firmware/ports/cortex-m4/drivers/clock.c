/* SPDX-License-Identifier: MIT */
#include "clock.h"

#include <stddef.h>

#include "stm32g431_regs.h"

#define HSI16_HZ 16000000u
#define PLL_IN_HZ 4000000u /* VCO input: within 2.66 .. 8 MHz for any M */
#define PLL_N 85u          /* 4 MHz x 85 = 340 MHz VCO (96 .. 344 MHz) */
#define PLL_HZ 170000000u  /* VCO / R 2 */
#define HSE_MAX_HZ 48000000u
#define PLLSRC_HSI16 2u
#define PLLSRC_HSE 3u
#define SW_HSI16 1u
#define SW_HSE 2u
#define SW_PLL 3u
#define HPRE_DIV2 8u
#define FLASH_WAIT_STATES 4u /* 170 MHz in range 1 boost (RM0440 table 29) */
#define LPTIM1SEL_HSI16 2u
#define LPTIM_PRESC_128 7u
/* The crystal is timed over 1,000 periods of HSI16 / 128 (8 ms), in SysTick ticks of HCLK = crystal / 2.
 * The prescaler keeps LPTIM1's count slower than the bus that reads it, so that two reads in a row can agree
 * (the check RM0440 asks for on an asynchronous counter). A crystal is taken as the nearest multiple of
 * 4 MHz when within 3 %: HSI16's own error (+-1 % over temperature, RM0440 and the datasheet) with room to
 * spare, and far from the next candidate (8 and 12 MHz are 40 % apart). */
#define TIMING_COUNTS 1000u
#define TIMING_KHZ_PER_TICK_COUNT 250u /* kHz = ticks x 2 x (16 MHz / 128) / counts / 1000 */
#define TIMING_TOLERANCE_PCT 3u

pour_clock_config_t pour_clock_default_config(void) {
  pour_clock_config_t c;
  c.ready_polls = 100000u;
  return c;
}

uint32_t pour_clock_crystal_hz(uint32_t measured_hz) {
  const uint32_t n = (measured_hz + PLL_IN_HZ / 2u) / PLL_IN_HZ;
  const uint32_t nominal = n * PLL_IN_HZ;
  const uint32_t error = measured_hz > nominal ? measured_hz - nominal : nominal - measured_hz;
  if (n == 0u || nominal > HSE_MAX_HZ || error > nominal / 100u * TIMING_TOLERANCE_PCT) {
    return 0u;
  }
  return nominal;
}

static int switch_to(volatile uint32_t *rcc, uint32_t sw, uint32_t polls) {
  rcc[POUR_RCC_CFGR] = (rcc[POUR_RCC_CFGR] & ~POUR_MSK(RCC, CFGR, SW)) | POUR_VAL(RCC, CFGR, SW, sw);
  return pour_regs_wait(&rcc[POUR_RCC_CFGR], POUR_MSK(RCC, CFGR, SWS), POUR_VAL(RCC, CFGR, SWS, sw), polls);
}

/* One sample of both counters: LPTIM1's count read before and after SysTick's; 1 if the two reads agree (no
 * count was missed between them), else 0 and the sample is not to be used. */
static int sample(const volatile uint32_t *lptim, const volatile uint32_t *systick, uint32_t *count,
                  uint32_t *ticks_left) {
  const uint32_t before = lptim[POUR_LPTIM_CNT];
  *ticks_left = systick[POUR_SYST_CVR];
  const uint32_t after = lptim[POUR_LPTIM_CNT];
  *count = POUR_GET(LPTIM, CNT, CNT, after);
  return before == after;
}

/* The crystal's frequency [Hz], measured with the core running from it: SysTick counts HCLK (the crystal
 * / 2) while LPTIM1 counts HSI16 / 128, an independent oscillator. 0 if the timing did not finish within
 * polls (a counter that does not run, or a crystal far above 48 MHz). Leaves the core on HSI16. */
static uint32_t time_crystal(const pour_clock_hw_t *hw, uint32_t polls) {
  volatile uint32_t *const rcc = hw->rcc, *const lp = hw->lptim, *const st = hw->systick;
  uint32_t hz = 0u;
  if (switch_to(rcc, SW_HSE, polls) == 0) {
    rcc[POUR_RCC_APB1ENR1] |= POUR_MSK(RCC, APB1ENR1, LPTIM1EN);
    rcc[POUR_RCC_CCIPR] = (rcc[POUR_RCC_CCIPR] & ~POUR_MSK(RCC, CCIPR, LPTIM1SEL)) |
                          POUR_VAL(RCC, CCIPR, LPTIM1SEL, LPTIM1SEL_HSI16);
    lp[POUR_LPTIM_CFGR] = POUR_VAL(LPTIM, CFGR, PRESC, LPTIM_PRESC_128); /* written while disabled */
    lp[POUR_LPTIM_CR] = POUR_MSK(LPTIM, CR, ENABLE);
    lp[POUR_LPTIM_ARR] = POUR_MSK(LPTIM, ARR, ARR); /* ARR is written once enabled (RM0440 LPTIM) */
    const uint32_t arrok = POUR_MSK(LPTIM, ISR, ARROK);
    if (pour_regs_wait(&lp[POUR_LPTIM_ISR], arrok, arrok, polls) == 0) {
      lp[POUR_LPTIM_CR] = POUR_MSK(LPTIM, CR, ENABLE) | POUR_MSK(LPTIM, CR, CNTSTRT);
      st[POUR_SYST_RVR] = POUR_SYST_MAX;
      st[POUR_SYST_CVR] = 0u;
      st[POUR_SYST_CSR] = POUR_SYST_CSR_ENABLE | POUR_SYST_CSR_CLKSOURCE_CORE;
      uint32_t c0 = 0u, s0 = 0u, c, s, i = 0u;
      while (!sample(lp, st, &c0, &s0) && ++i < polls) {
      }
      const uint32_t max_ticks = HSE_MAX_HZ / 2u / 1000u * 8u * 2u; /* twice 8 ms of a 48 MHz crystal */
      for (i = 0u; i < polls; ++i) {
        if (!sample(lp, st, &c, &s)) {
          continue;
        }
        const uint32_t counts = (c - c0) & POUR_MSK(LPTIM, CNT, CNT);
        const uint32_t ticks = (s0 - s) & POUR_SYST_MAX;
        if (counts >= TIMING_COUNTS) {
          hz = ticks * TIMING_KHZ_PER_TICK_COUNT / counts * 1000u;
          break;
        }
        if (ticks > max_ticks) {
          break;
        }
      }
    }
    st[POUR_SYST_CSR] = 0u;
    lp[POUR_LPTIM_CR] = 0u;
    rcc[POUR_RCC_APB1ENR1] &= ~POUR_MSK(RCC, APB1ENR1, LPTIM1EN);
  }
  (void)switch_to(rcc, SW_HSI16, polls);
  return hz;
}

/* The PLL never came: the core stays on HSI16 at AHB /1, and says so (no crystal in use). */
static pour_status_t stay_on_hsi16(volatile uint32_t *rcc, pour_clock_source_t *source, uint32_t *crystal_hz) {
  rcc[POUR_RCC_CFGR] &= ~POUR_MSK(RCC, CFGR, HPRE);
  *source = POUR_CLOCK_HSI16;
  *crystal_hz = 0u;
  return POUR_EINVAL;
}

static void pll_from(volatile uint32_t *rcc, uint32_t src, uint32_t in_hz) {
  rcc[POUR_RCC_PLLCFGR] = POUR_VAL(RCC, PLLCFGR, PLLSRC, src) | POUR_VAL(RCC, PLLCFGR, PLLM, in_hz / PLL_IN_HZ - 1u) |
                          POUR_VAL(RCC, PLLCFGR, PLLN, PLL_N) | POUR_MSK(RCC, PLLCFGR, PLLREN) |
                          POUR_VAL(RCC, PLLCFGR, PLLR, 0u); /* R /2 */
}

pour_status_t pour_clock_setup(const pour_clock_hw_t *hw, const pour_clock_config_t *config, uint32_t *core_clock_hz,
                               pour_clock_source_t *source, uint32_t *crystal_hz) {
  if (hw == NULL || config == NULL || core_clock_hz == NULL || source == NULL || crystal_hz == NULL) {
    return POUR_EINVAL;
  }
  *core_clock_hz = HSI16_HZ;
  *source = POUR_CLOCK_HSI16;
  *crystal_hz = 0u;
  if (config->ready_polls == 0u) {
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
  /* The crystal first, timed against HSI16 so that the PLL divides whatever frequency is fitted down to
   * its 4 MHz input; the clock security system then watches it (a crystal that stops later hands the core
   * to HSI16 in hardware and raises the NMI, which startup.c turns into the safe outputs). */
  rcc[POUR_RCC_CR] = (rcc[POUR_RCC_CR] & ~POUR_MSK(RCC, CR, HSEBYP)) | POUR_MSK(RCC, CR, HSEON);
  const uint32_t hserdy = POUR_MSK(RCC, CR, HSERDY);
  if (pour_regs_wait(&rcc[POUR_RCC_CR], hserdy, hserdy, polls) == 0) {
    *crystal_hz = pour_clock_crystal_hz(time_crystal(hw, polls));
  }
  if (*crystal_hz != 0u) {
    pll_from(rcc, PLLSRC_HSE, *crystal_hz);
    rcc[POUR_RCC_CR] |= POUR_MSK(RCC, CR, CSSON);
    *source = POUR_CLOCK_HSE;
  } else {
    rcc[POUR_RCC_CR] &= ~POUR_MSK(RCC, CR, HSEON);
    pll_from(rcc, PLLSRC_HSI16, HSI16_HZ);
  }
  rcc[POUR_RCC_CR] |= POUR_MSK(RCC, CR, PLLON);
  const uint32_t pllrdy = POUR_MSK(RCC, CR, PLLRDY);
  if (pour_regs_wait(&rcc[POUR_RCC_CR], pllrdy, pllrdy, polls) != 0) {
    return stay_on_hsi16(rcc, source, crystal_hz);
  }
  if (switch_to(rcc, SW_PLL, polls) != 0) {
    return stay_on_hsi16(rcc, source, crystal_hz);
  }
  for (volatile uint32_t i = 0; i < 200u; ++i) { /* >= 1 µs at 85 MHz before HPRE /1 (RM0440 §6.2.7) */
  }
  rcc[POUR_RCC_CFGR] &= ~(hpre | POUR_MSK(RCC, CFGR, PPRE1) | POUR_MSK(RCC, CFGR, PPRE2)); /* 170 MHz everywhere */
  *core_clock_hz = PLL_HZ;
  return POUR_OK;
}
