/* SPDX-License-Identifier: MIT */
/* The overcurrent comparators and their DAC3 thresholds against register files: the threshold from the
 * measured offset, the comparators' inputs, a DAC that never becomes ready, a trip beyond full scale. */
#include <string.h>

#include "ocp.h"
#include "unity.h"

static uint32_t comp[POUR_OCP_COMP_N_REGS], dac[POUR_OCP_DAC_N_REGS];
static pour_ocp_t ocp;
static const uint16_t offsets[3] = {2048u, 2000u, 2080u};

void setUp(void) {
  memset(comp, 0, sizeof comp);
  memset(dac, 0, sizeof dac);
  dac[POUR_DAC_SR] = (1u << 11) | (1u << 27); /* both channels ready */
}

void tearDown(void) {}

static void test_ocp_threshold_code_IsBiasPlusTripCurrentTimesShunt(void) {
  const pour_ocp_config_t c = pour_ocp_default_config();
  /* bias 2048 / 9.14 = 224.1 counts; 40 A x 3 mΩ = 120 mV = 148.9 counts of 3.3 V */
  TEST_ASSERT_EQUAL_UINT16(373u, pour_ocp_threshold_code(&c, 2048u));
  TEST_ASSERT_EQUAL_UINT16(149u, pour_ocp_threshold_code(&c, 0u));
}

static void test_ocp_init_ArmsTheComparatorsOnDac3(void) {
  const pour_ocp_config_t c = pour_ocp_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_ocp_init(&ocp, comp, dac, &c, offsets));
  TEST_ASSERT_EQUAL_HEX32(3u | (3u << 16), dac[POUR_DAC_MCR]); /* internal, no buffer */
  TEST_ASSERT_EQUAL_HEX32(373u, dac[POUR_DAC_DHR12R1]);
  TEST_ASSERT_EQUAL_HEX32(pour_ocp_threshold_code(&c, 2080u), dac[POUR_DAC_DHR12R2]); /* V and W: the larger */
  TEST_ASSERT_EQUAL_HEX32(1u | (1u << 16), dac[POUR_DAC_CR]);
  const uint32_t csr = 1u | (4u << 4) | (1u << 16); /* EN, INM DAC3, INP pin 0, 10 mV hysteresis */
  TEST_ASSERT_EQUAL_HEX32(csr, comp[POUR_COMP_C1CSR]);
  TEST_ASSERT_EQUAL_HEX32(csr, comp[POUR_COMP_C2CSR]);
  TEST_ASSERT_EQUAL_HEX32(csr, comp[POUR_COMP_C4CSR]);
  TEST_ASSERT_FALSE(pour_ocp_tripping(&ocp));
  comp[POUR_COMP_C4CSR] |= 1u << 30; /* phase W above its threshold */
  TEST_ASSERT_TRUE(pour_ocp_tripping(&ocp));
}

static void test_ocp_init_RefusesAnUnreadyDacOrAnUnreachableTrip(void) {
  pour_ocp_config_t c = pour_ocp_default_config();
  dac[POUR_DAC_SR] = 1u << 11;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_ocp_init(&ocp, comp, dac, &c, offsets));
  TEST_ASSERT_EQUAL_HEX32(0u, comp[POUR_COMP_C1CSR]); /* comparators never armed on a bad threshold */
  dac[POUR_DAC_SR] = (1u << 11) | (1u << 27);
  c.trip_ma = 1200000u; /* 3.6 V across the shunt: beyond the DAC's 3.3 V */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_ocp_init(&ocp, comp, dac, &c, offsets));
  c = pour_ocp_default_config();
  c.amp_gain_milli = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_ocp_init(&ocp, comp, dac, &c, offsets));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_ocp_threshold_code_IsBiasPlusTripCurrentTimesShunt);
  RUN_TEST(test_ocp_init_ArmsTheComparatorsOnDac3);
  RUN_TEST(test_ocp_init_RefusesAnUnreadyDacOrAnUnreachableTrip);
  return UNITY_END();
}
