/* SPDX-License-Identifier: MIT */
#include "boot_check.h"

#include "stm32g431_regs.h"

pour_status_t pour_boot_check_optr(uint32_t optr) {
  const uint32_t pin_decides = POUR_GET(FLASH, OPTR, N_SWBOOT0, optr);
  const uint32_t main_flash = POUR_GET(FLASH, OPTR, N_BOOT0, optr);
  return pin_decides == 0u && main_flash == 1u ? POUR_OK : POUR_EBOOT;
}
