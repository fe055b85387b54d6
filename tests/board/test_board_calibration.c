/* SPDX-License-Identifier: MIT */
/* The calibration block in a flash page in plain memory (the real flash driver on a register file): a
 * round trip, and each refusal: none stored, a flipped bit, an older format, results out of range (on save
 * and on load), a write the flash refuses. */
#include <string.h>

#include "calibration_store.h"
#include "flash_page_file.h"
#include "unity.h"

static pour_calibration_t good;

void setUp(void) {
  flash_page_file_reset();
  good.r_phase_uohm = 304000u;
  good.l_phase_nh = 231500u;
  good.encoder_direction = -1;
  good.pole_pairs = 8u;
  good.electrical_offset = 12345u;
}

void tearDown(void) {}

static void test_calibration_SavesAndLoadsTheSameResults(void) {
  pour_calibration_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_EMPTY, pour_calibration_load(&f, &got));
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  memset(&got, 0, sizeof got);
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_load(&f, &got));
  TEST_ASSERT_EQUAL_MEMORY(&good, &got, sizeof good);
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, page[POUR_CAL_BLOCK_WORDS]); /* nothing past the block */
}

static void test_calibration_crc32_IsTheStandardOne(void) {
  const uint32_t w[2] = {0x34333231u, 0x38373635u}; /* "12345678" */
  TEST_ASSERT_EQUAL_HEX32(0x9AE0DAAFu, pour_calibration_crc32(w, 2u));
}

static void test_calibration_load_RefusesAFlippedBit(void) {
  pour_calibration_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  page[3] ^= 1u << 7;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_CORRUPT, pour_calibration_load(&f, &got));
  page[3] ^= 1u << 7;
  page[0] = 0x12345678u; /* not ours at all */
  TEST_ASSERT_EQUAL_INT(POUR_CAL_CORRUPT, pour_calibration_load(&f, &got));
}

static void test_calibration_load_RefusesAnOlderFormat(void) {
  pour_calibration_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  page[1] = POUR_CAL_FORMAT_VERSION - 1u;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OLD_VERSION, pour_calibration_load(&f, &got));
}

static void test_calibration_RefusesResultsOutOfRange(void) {
  pour_calibration_t bad = good;
  bad.pole_pairs = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OUT_OF_RANGE, pour_calibration_save(&f, &bad));
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, page[0]); /* nothing written */
  bad = good;
  bad.r_phase_uohm = 20000000u; /* 20 Ω: an open phase */
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OUT_OF_RANGE, pour_calibration_check(&bad));
  bad = good;
  bad.encoder_direction = 0;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OUT_OF_RANGE, pour_calibration_check(&bad));
  /* A block with a good CRC around a result out of range (written by a buggy tool): refused on load. */
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  page[5] = 40u;
  page[POUR_CAL_BLOCK_WORDS - 1u] = pour_calibration_crc32(page, POUR_CAL_BLOCK_WORDS - 1u);
  pour_calibration_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OUT_OF_RANGE, pour_calibration_load(&f, &got));
}

static void test_calibration_save_ReportsAFailedWrite(void) {
  regs[POUR_FLASH_SR] = 1u << 4; /* WRPERR: the page is write-protected */
  TEST_ASSERT_EQUAL_INT(POUR_CAL_WRITE_FAILED, pour_calibration_save(&f, &good));
  pour_calibration_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAL_EMPTY, pour_calibration_load(&f, &got)); /* no valid block left behind */
}

static void test_calibration_can_result_CarriesTheStoredValuesRounded(void) {
  pour_can_calibration_result_t r;
  pour_calibration_can_result(POUR_CAL_OK, &good, POUR_CAN_CAL_MEASURING, &r);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, r.status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, r.stored);
  TEST_ASSERT_EQUAL_UINT8(1u, r.encoder_reversed);
  TEST_ASSERT_EQUAL_UINT8(8u, r.pole_pairs);
  TEST_ASSERT_EQUAL_UINT16(304u, r.resistance_mohm);
  TEST_ASSERT_EQUAL_UINT16(232u, r.inductance_uh);   /* 231.5 µH, to nearest */
  TEST_ASSERT_EQUAL_UINT8(48u, r.electrical_offset); /* 12345/256 = 48.2 */
  pour_calibration_t top = good;
  top.electrical_offset = 65500u; /* 255.9: to nearest wraps to 0 */
  pour_calibration_can_result(POUR_CAL_OK, &top, POUR_CAN_CAL_OK, &r);
  TEST_ASSERT_EQUAL_UINT8(0u, r.electrical_offset);
  /* nothing valid stored: no values, whatever the struct holds */
  pour_calibration_can_result(POUR_CAL_CORRUPT, &good, POUR_CAN_CAL_OK, &r);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_CORRUPT, r.stored);
  TEST_ASSERT_EQUAL_UINT8(0u, r.pole_pairs);
  TEST_ASSERT_EQUAL_UINT16(0u, r.resistance_mohm);
  TEST_ASSERT_EQUAL_UINT8(0u, r.encoder_reversed);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_calibration_SavesAndLoadsTheSameResults);
  RUN_TEST(test_calibration_crc32_IsTheStandardOne);
  RUN_TEST(test_calibration_load_RefusesAFlippedBit);
  RUN_TEST(test_calibration_load_RefusesAnOlderFormat);
  RUN_TEST(test_calibration_RefusesResultsOutOfRange);
  RUN_TEST(test_calibration_save_ReportsAFailedWrite);
  RUN_TEST(test_calibration_can_result_CarriesTheStoredValuesRounded);
  return UNITY_END();
}
