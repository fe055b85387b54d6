/* SPDX-License-Identifier: MIT */
/* OPAMP1..3 as PGAs against a register file: the gain codes, PGA mode, high speed, output on the pin. */
#include <string.h>

#include "opamp.h"
#include "unity.h"

static uint32_t regs[POUR_OPAMP_N_REGS];

void setUp(void) { memset(regs, 0, sizeof regs); }

void tearDown(void) {}

static void test_opamp_init_SetsAllThreeAsPgasOfTheGain(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 16u));
  const uint32_t want = 1u | (2u << 5) | (1u << 7) | (3u << 14); /* OPAEN, VM_SEL PGA, OPAHSM, gain 16 */
  TEST_ASSERT_EQUAL_HEX32(want, regs[POUR_OPAMP_OPAMP1_CSR]);
  TEST_ASSERT_EQUAL_HEX32(want, regs[POUR_OPAMP_OPAMP2_CSR]);
  TEST_ASSERT_EQUAL_HEX32(want, regs[POUR_OPAMP_OPAMP3_CSR]);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 2u));
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_OPAMP_OPAMP1_CSR] & (0x1Fu << 14));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 64u));
  TEST_ASSERT_EQUAL_HEX32(5u << 14, regs[POUR_OPAMP_OPAMP3_CSR] & (0x1Fu << 14));
}

static void test_opamp_init_GainZeroUsesTheBoardsNetwork(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 0u));
  TEST_ASSERT_EQUAL_HEX32(1u | (1u << 7), regs[POUR_OPAMP_OPAMP2_CSR]); /* OPAEN, VM_SEL VINM0, OPAHSM */
}

static void test_opamp_init_RefusesAGainItCannotSet(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_opamp_init(regs, 10u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_opamp_init(regs, 128u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_opamp_init(regs, 1u));
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_OPAMP_OPAMP1_CSR]); /* nothing enabled */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_opamp_init(NULL, 16u));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_opamp_init_SetsAllThreeAsPgasOfTheGain);
  RUN_TEST(test_opamp_init_GainZeroUsesTheBoardsNetwork);
  RUN_TEST(test_opamp_init_RefusesAGainItCannotSet);
  return UNITY_END();
}
