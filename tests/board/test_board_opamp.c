/* SPDX-License-Identifier: MIT */
/* OPAMP1..3 as PGAs against a register file: the gain codes with the input/bias on VINM0, PGA mode, high
 * speed, output on the pin; the board's gain from pour/board_facts.h. */
#include <string.h>

#include "opamp.h"
#include "pour/board_facts.h"
#include "unity.h"

static uint32_t regs[POUR_OPAMP_N_REGS];

void setUp(void) { memset(regs, 0, sizeof regs); }

void tearDown(void) {}

static void test_opamp_init_SetsAllThreeAsPgasOfTheGain(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 16u));
  /* OPAEN, VM_SEL PGA, OPAHSM, PGA_GAIN 0b01011: gain 16, input/bias on VINM0 (RM0440) */
  const uint32_t want = 1u | (2u << 5) | (1u << 7) | (11u << 14);
  TEST_ASSERT_EQUAL_HEX32(want, regs[POUR_OPAMP_OPAMP1_CSR]);
  TEST_ASSERT_EQUAL_HEX32(want, regs[POUR_OPAMP_OPAMP2_CSR]);
  TEST_ASSERT_EQUAL_HEX32(want, regs[POUR_OPAMP_OPAMP3_CSR]);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 2u));
  TEST_ASSERT_EQUAL_HEX32(8u << 14, regs[POUR_OPAMP_OPAMP1_CSR] & (0x1Fu << 14));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, 64u));
  TEST_ASSERT_EQUAL_HEX32(13u << 14, regs[POUR_OPAMP_OPAMP3_CSR] & (0x1Fu << 14));
}

/* The old open loop (VM_SEL VINM0 with no feedback network on the board: the ADC reads a rail) is refused. */
static void test_opamp_init_NeverLeavesTheAmplifierOpenLoop(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_opamp_init(regs, 0u));
  TEST_ASSERT_EQUAL_HEX32(0u, regs[POUR_OPAMP_OPAMP2_CSR]);
  TEST_ASSERT_EQUAL_INT(16, POUR_BOARD_PGA_GAIN);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_opamp_init(regs, POUR_BOARD_PGA_GAIN));
  TEST_ASSERT_EQUAL_HEX32(2u, (regs[POUR_OPAMP_OPAMP2_CSR] >> 5) & 3u); /* VM_SEL: PGA */
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
  RUN_TEST(test_opamp_init_NeverLeavesTheAmplifierOpenLoop);
  RUN_TEST(test_opamp_init_RefusesAGainItCannotSet);
  return UNITY_END();
}
