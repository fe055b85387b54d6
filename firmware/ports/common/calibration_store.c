/* SPDX-License-Identifier: MIT */
#include "calibration_store.h"

#include <stdbool.h>
#include <stddef.h>

#define MAGIC 0x4C414350u /* "PCAL" */
#define CRC_WORD (POUR_CAL_BLOCK_WORDS - 1u)

uint32_t pour_calibration_crc32(const uint32_t *words, uint32_t n) {
  uint32_t crc = 0xFFFFFFFFu;
  for (uint32_t i = 0; i < n; ++i) {
    for (unsigned b = 0; b < 4u; ++b) {
      crc ^= (words[i] >> (8u * b)) & 0xFFu;
      for (unsigned k = 0; k < 8u; ++k) {
        crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
      }
    }
  }
  return ~crc;
}

pour_cal_status_t pour_calibration_check(const pour_calibration_t *c) {
  if (c == NULL || c->r_phase_uohm < 10000u || c->r_phase_uohm > 10000000u || c->l_phase_nh < 10000u ||
      c->l_phase_nh > 10000000u || (c->encoder_direction != 1 && c->encoder_direction != -1) || c->pole_pairs < 1u ||
      c->pole_pairs > 32u || c->electrical_offset > 0xFFFFu) {
    return POUR_CAL_OUT_OF_RANGE;
  }
  return POUR_CAL_OK;
}

static void pack(const pour_calibration_t *c, uint32_t w[POUR_CAL_BLOCK_WORDS]) {
  w[0] = MAGIC;
  w[1] = POUR_CAL_FORMAT_VERSION;
  w[2] = c->r_phase_uohm;
  w[3] = c->l_phase_nh;
  w[4] = (uint32_t)c->encoder_direction;
  w[5] = c->pole_pairs;
  w[6] = c->electrical_offset;
  w[CRC_WORD] = pour_calibration_crc32(w, CRC_WORD);
}

pour_cal_status_t pour_calibration_load(const pour_flash_t *flash, pour_calibration_t *cal) {
  if (flash == NULL || flash->page == NULL || cal == NULL) {
    return POUR_CAL_CORRUPT;
  }
  uint32_t w[POUR_CAL_BLOCK_WORDS];
  uint32_t blank = 0xFFFFFFFFu;
  for (uint32_t i = 0; i < POUR_CAL_BLOCK_WORDS; ++i) {
    w[i] = flash->page[i];
    blank &= w[i];
  }
  if (blank == 0xFFFFFFFFu) {
    return POUR_CAL_EMPTY;
  }
  if (w[0] != MAGIC) {
    return POUR_CAL_CORRUPT;
  }
  if (w[1] != POUR_CAL_FORMAT_VERSION) {
    return POUR_CAL_OLD_VERSION; /* another layout: its CRC is not where this one's is */
  }
  if (w[CRC_WORD] != pour_calibration_crc32(w, CRC_WORD)) {
    return POUR_CAL_CORRUPT;
  }
  pour_calibration_t c;
  c.r_phase_uohm = w[2];
  c.l_phase_nh = w[3];
  c.encoder_direction = (int32_t)w[4];
  c.pole_pairs = w[5];
  c.electrical_offset = w[6];
  if (pour_calibration_check(&c) != POUR_CAL_OK) {
    return POUR_CAL_OUT_OF_RANGE;
  }
  *cal = c;
  return POUR_CAL_OK;
}

void pour_calibration_can_result(pour_cal_status_t stored, const pour_calibration_t *cal, uint8_t status,
                                 pour_can_calibration_result_t *r) {
  const bool ok = stored == POUR_CAL_OK && cal != NULL;
  r->status = status;
  r->stored = (uint8_t)stored; /* POUR_CAN_CAL_OK .. _WRITE_FAILED are pour_cal_status_t's values */
  r->encoder_reversed = ok && cal->encoder_direction < 0 ? 1u : 0u;
  r->pole_pairs = ok ? (uint8_t)cal->pole_pairs : 0u;
  r->resistance_mohm = ok ? (uint16_t)((cal->r_phase_uohm + 500u) / 1000u) : 0u;
  r->inductance_uh = ok ? (uint16_t)((cal->l_phase_nh + 500u) / 1000u) : 0u;
  r->electrical_offset = ok ? (uint8_t)(((cal->electrical_offset + 128u) >> 8) & 0xFFu) : 0u;
}

pour_cal_status_t pour_calibration_save(const pour_flash_t *flash, const pour_calibration_t *cal) {
  if (pour_calibration_check(cal) != POUR_CAL_OK) {
    return POUR_CAL_OUT_OF_RANGE;
  }
  uint32_t w[POUR_CAL_BLOCK_WORDS];
  pack(cal, w);
  if (pour_flash_write_page(flash, w, POUR_CAL_BLOCK_WORDS) != POUR_FLASH_OK) {
    return POUR_CAL_WRITE_FAILED;
  }
  return POUR_CAL_OK;
}
