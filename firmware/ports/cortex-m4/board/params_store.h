/* SPDX-License-Identifier: MIT */
/* The parameters in flash, beside the calibration: the blob of pour_params_serialize (magic "PPRM", layout
 * version, count, (id, value) pairs, CRC-32; docs/can.md, "Storage") in its own 2 KB page, 62, the one before
 * the calibration's (the linker script leaves both), padded with 0xFF to whole double words. The same flash
 * driver as the calibration's (flash_g4.c): a page erase stalls the single-bank G431's reads for its
 * duration, so a ParamSave is taken only in IDLE or FAULT (the drive's interrupt holds the bridge off or
 * the brake engaged), like a calibration's store. */
#ifndef POUR_PARAMS_STORE_H
#define POUR_PARAMS_STORE_H

#include "flash_g4.h"
#include "pour/params.h"

#define POUR_FLASH_PARAMS_PAGE 62u
#define POUR_FLASH_PARAMS_ADDR 0x0801F000u

/* Reads the page onto *params: POUR_PARAMS_BLOB_OK, or 1 for a blank page (never saved: *params as it
 * was), or the blob's error (*params untouched; *bad_id names the parameter of BAD_VALUE). */
int pour_params_store_load(const pour_flash_t *flash, pour_params_t *params, uint8_t *bad_id);

/* Replaces the page's content with *params: POUR_FLASH_OK, or POUR_FLASH_FAILED (erase, program or read-back
 * failed: no valid set stored). */
int pour_params_store_save(const pour_flash_t *flash, const pour_params_t *params);

#endif /* POUR_PARAMS_STORE_H */
