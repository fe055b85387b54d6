/* SPDX-License-Identifier: MIT */
/* The option bytes the B-G431B-ESC1 needs to boot this firmware whatever PB8 reads. PB8 is BOOT0 with the
 * board's 10 kΩ pull-up (pour/board_facts.h) and carries the e-stop here: with nSWBOOT0 = 1 the pin decides,
 * and an e-stop held open through a reset (or a broken wire) would boot the ROM bootloader (nBOOT1 = 1) or
 * SRAM. So the board needs nSWBOOT0 = 0 (BOOT0 taken from the nBOOT0 bit) and nBOOT0 = 1 (main flash). The
 * chip's factory value (RM0440: 0xFFEFF8AA) has nSWBOOT0 = 1, the pin deciding. Anything but the board's
 * needs is reported (Identity.InitStatus = POUR_EBOOT) and the controller never runs: docs/bringup.md says
 * how to set them (STM32CubeProgrammer or openocd's stm32l4x option_write). */
#ifndef POUR_BOOT_CHECK_H
#define POUR_BOOT_CHECK_H

#include <stdint.h>

#include "pour/fixed.h"

/* POUR_OK if FLASH_OPTR's boot bits (as read from the option register) boot main flash whatever BOOT0's pin
 * reads; POUR_EBOOT if they let the pin choose, or choose the ROM bootloader or SRAM themselves. */
pour_status_t pour_boot_check_optr(uint32_t optr);

/* The chip's own option register, checked (the board's; the QEMU bench's is its own). */
pour_status_t pour_hal_boot_check(void);

#endif /* POUR_BOOT_CHECK_H */
