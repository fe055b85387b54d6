/* SPDX-License-Identifier: MIT */
/* The independent watchdog (IWDG) over its registers (stm32g431_regs.h's table; a register file in
 * tests/board/test_board_iwdg.c). It counts LSI, which the datasheet allows anywhere from 29.5 to 34 kHz: a
 * timeout is programmed for the fastest LSI (pour/board_facts.h), so it is never shorter than asked. */
#ifndef POUR_IWDG_H
#define POUR_IWDG_H

#include <stdint.h>

#include "pour/fixed.h"

#define POUR_IWDG_PRESCALER_CODE 0u /* PR 0: LSI / 4 */
#define POUR_IWDG_RELOAD_MAX 4095u

/* The reload (RLR) whose timeout at the fastest LSI is at least timeout_ms [ms]; 0 if it does not fit. */
uint32_t pour_iwdg_reload(uint32_t timeout_ms);

/* The timeout [µs] that PR = prescaler_code and RLR = reload give on an LSI of lsi_hz. */
uint32_t pour_iwdg_timeout_us(uint32_t prescaler_code, uint32_t reload, uint32_t lsi_hz);

/* Starts the watchdog if it is not running and sets its timeout to at least timeout_ms (1 .. 480 ms), then
 * reloads it; waits (at most polls reads) for the new values to reach the IWDG's clock domain. POUR_EINVAL
 * for a timeout out of range or values that never settle. */
pour_status_t pour_iwdg_set(volatile uint32_t *iwdg, uint32_t timeout_ms, uint32_t polls);

#endif /* POUR_IWDG_H */
