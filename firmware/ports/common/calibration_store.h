/* SPDX-License-Identifier: MIT */
/* The drive's calibration in flash: one block (magic, format version, the results, CRC-32) in the page the
 * linker script leaves free, checked when it is loaded at boot and refused with a reason: none stored,
 * corrupt, an older format, or results outside their plausible ranges. A save erases, programs and reads
 * back; a flash that fails says so and leaves no valid block. */
#ifndef POUR_CALIBRATION_STORE_H
#define POUR_CALIBRATION_STORE_H

#include <stdint.h>

#include "flash_g4.h"
#include "pour/can_codec.h"

#define POUR_CAL_FORMAT_VERSION 1u

typedef enum {
  POUR_CAL_OK = 0,
  POUR_CAL_EMPTY = 1,        /* the page is blank: never calibrated */
  POUR_CAL_CORRUPT = 2,      /* magic or CRC-32 wrong */
  POUR_CAL_OLD_VERSION = 3,  /* written by another format version */
  POUR_CAL_OUT_OF_RANGE = 4, /* a result outside its plausible range */
  POUR_CAL_WRITE_FAILED = 5  /* the flash refused the erase or the program, or read back otherwise */
} pour_cal_status_t;

/* What calibration measures, as the motor library needs it. */
typedef struct {
  uint32_t r_phase_uohm;      /* phase resistance [µΩ], 10 mΩ .. 10 Ω */
  uint32_t l_phase_nh;        /* phase inductance [nH], 10 µH .. 10 mH */
  int32_t encoder_direction;  /* +1: the count rises with the electrical angle; -1: falls */
  uint32_t pole_pairs;        /* 1 .. 32 */
  uint32_t electrical_offset; /* electrical angle at encoder count 0, 65536 = 2π: 0 .. 65535 */
} pour_calibration_t;

/* The block's size in words (magic, version, 5 results, CRC; padded to double words). */
#define POUR_CAL_BLOCK_WORDS 8u

/* POUR_CAL_OK or POUR_CAL_OUT_OF_RANGE. */
pour_cal_status_t pour_calibration_check(const pour_calibration_t *cal);

/* Reads and checks the block; *cal is written only when POUR_CAL_OK. */
pour_cal_status_t pour_calibration_load(const pour_flash_t *flash, pour_calibration_t *cal);

/* Checks, erases, programs, reads back: POUR_CAL_OK, POUR_CAL_OUT_OF_RANGE (nothing written) or
 * POUR_CAL_WRITE_FAILED. */
pour_cal_status_t pour_calibration_save(const pour_flash_t *flash, const pour_calibration_t *cal);

/* The CalibrationResult that says status (POUR_CAN_CAL_*) beside the stored block's state and, when it is
 * POUR_CAL_OK, its values (R in mΩ, L in µH, the offset's top 8 bits). */
void pour_calibration_can_result(pour_cal_status_t stored, const pour_calibration_t *cal, uint8_t status,
                                 pour_can_calibration_result_t *result);

/* CRC-32 (IEEE 802.3, reflected, initial and final 0xFFFFFFFF) of n little-endian words. */
uint32_t pour_calibration_crc32(const uint32_t *words, uint32_t n);

#endif /* POUR_CALIBRATION_STORE_H */
