/* SPDX-License-Identifier: MIT */
#include "params_store.h"

#include <stddef.h>
#include <string.h>

#define BLOB_WORDS (((POUR_PARAMS_BLOB_MAX + 7u) / 8u) * 2u) /* the largest blob, in whole double words */

int pour_params_store_load(const pour_flash_t *flash, pour_params_t *params, uint8_t *bad_id) {
  if (flash == NULL || flash->page == NULL || params == NULL || bad_id == NULL) {
    return POUR_PARAMS_BLOB_TRUNCATED;
  }
  uint32_t w[BLOB_WORDS];
  uint32_t blank = 0xFFFFFFFFu;
  for (uint32_t i = 0; i < BLOB_WORDS; ++i) {
    w[i] = flash->page[i];
    blank &= w[i];
  }
  if (blank == 0xFFFFFFFFu) {
    return 1;
  }
  const uint8_t *buf = (const uint8_t *)w; /* little-endian, as the blob (one copy on the stack, not two) */
  /* The blob's own length from its header (count at bytes 6..7), within what a blob can be. */
  const uint32_t count = (uint32_t)buf[6] | ((uint32_t)buf[7] << 8);
  const uint32_t len = 8u + 5u * count + 4u;
  return pour_params_deserialize(buf, len > POUR_PARAMS_BLOB_MAX ? POUR_PARAMS_BLOB_MAX : len, params, bad_id);
}

int pour_params_store_save(const pour_flash_t *flash, const pour_params_t *params) {
  uint32_t w[BLOB_WORDS];
  uint8_t *buf = (uint8_t *)w; /* the blob's bytes in the words the flash programs (little-endian) */
  memset(buf, 0xFF, sizeof w);
  const uint32_t n = pour_params_serialize(params, buf, POUR_PARAMS_BLOB_MAX);
  if (n == 0u) {
    return POUR_FLASH_BAD_ARGS;
  }
  const uint32_t n_words = ((n + 7u) / 8u) * 2u;
  return pour_flash_write_page(flash, w, n_words);
}
