/* SPDX-License-Identifier: MIT */
#include "iwdg.h"

#include <stddef.h>

#include "pour/board_facts.h"
#include "stm32g431_regs.h"

#define KEY_START 0xCCCCu
#define KEY_UNLOCK 0x5555u
#define KEY_RELOAD 0xAAAAu

uint32_t pour_iwdg_reload(uint32_t timeout_ms) {
  /* counts of LSI / 4 at the fastest LSI, rounded up; RLR + 1 counts to the reset */
  const uint64_t counts = ((uint64_t)timeout_ms * POUR_BOARD_LSI_MAX_HZ + 3999u) / 4000u;
  return counts == 0u || counts > POUR_IWDG_RELOAD_MAX + 1u ? 0u : (uint32_t)(counts - 1u);
}

uint32_t pour_iwdg_timeout_us(uint32_t prescaler_code, uint32_t reload, uint32_t lsi_hz) {
  const uint64_t divider = 4u << (prescaler_code > 6u ? 6u : prescaler_code);
  return lsi_hz == 0u ? 0u : (uint32_t)(((uint64_t)reload + 1u) * divider * 1000000u / lsi_hz);
}

pour_status_t pour_iwdg_set(volatile uint32_t *iwdg, uint32_t timeout_ms, uint32_t polls) {
  const uint32_t reload = pour_iwdg_reload(timeout_ms);
  if (iwdg == NULL || timeout_ms == 0u || reload == 0u) {
    return POUR_EINVAL;
  }
  iwdg[POUR_IWDG_KR] = KEY_START; /* no effect once it runs */
  iwdg[POUR_IWDG_KR] = KEY_UNLOCK;
  iwdg[POUR_IWDG_PR] = POUR_VAL(IWDG, PR, PR, POUR_IWDG_PRESCALER_CODE);
  iwdg[POUR_IWDG_RLR] = POUR_VAL(IWDG, RLR, RL, reload);
  const uint32_t busy = POUR_MSK(IWDG, SR, PVU) | POUR_MSK(IWDG, SR, RVU) | POUR_MSK(IWDG, SR, WVU);
  const int settled = pour_regs_wait(&iwdg[POUR_IWDG_SR], busy, 0u, polls);
  iwdg[POUR_IWDG_KR] = KEY_RELOAD;
  return settled == 0 ? POUR_OK : POUR_EINVAL;
}
