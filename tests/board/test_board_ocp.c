/* SPDX-License-Identifier: MIT */
/* The overcurrent comparators and their DAC3 thresholds against register files: the threshold from the
 * measured offset, the trip current through the board's real amplifier chain (pour/board_facts.h: the
 * comparator watches the op-amp's input), the comparators' inputs, a DAC that never becomes ready, a trip
 * beyond full scale. */
#include <string.h>

#include "ocp.h"
#include "pour/board_facts.h"
#include "unity.h"

static uint32_t comp[POUR_OCP_COMP_N_REGS], dac[POUR_OCP_DAC_N_REGS];
static pour_ocp_t ocp;
static const uint16_t offsets[3] = {2553u, 2520u, 2590u}; /* a healthy board: 2.057 V x 4096 / 3.3 */

void setUp(void) {
  memset(comp, 0, sizeof comp);
  memset(dac, 0, sizeof dac);
  dac[POUR_DAC_SR] = (1u << 11) | (1u << 27); /* both channels ready */
}

void tearDown(void) {}

static void test_ocp_threshold_code_IsBiasPlusTripCurrentTimesShunt(void) {
  const pour_ocp_config_t c = pour_ocp_default_config();
  /* bias 2553 / 16 = 159.6 counts; 40 A x 3 mΩ x 0.571 = 68.5 mV = 85.0 counts of 3.3 V */
  TEST_ASSERT_EQUAL_UINT16(245u, pour_ocp_threshold_code(&c, 2553u));
  TEST_ASSERT_EQUAL_UINT16(85u, pour_ocp_threshold_code(&c, 0u));
}

/* The op-amp's input (the comparator's) at phase current ma [mA, into the motor], as the board builds it: the
 * bias the board's network puts there, and the shunt's voltage through the network, of the board's sign (the
 * input falls as current flows into the motor) [µV]. */
static int64_t comparator_input_uv(int64_t ma) {
  return POUR_BOARD_VINP_BIAS_UV +
         POUR_BOARD_CURRENT_SIGN * ma * POUR_BOARD_SHUNT_UOHM * POUR_BOARD_INPUT_NETWORK_MILLI / 1000000;
}

/* The current at which the comparator's output first goes high, swept outwards in 10 mA steps [mA]. */
static int64_t trip_current_ma(uint16_t dac_code) {
  const int64_t threshold_uv = (int64_t)dac_code * POUR_BOARD_ADC_VREF_MV * 1000 / 4096;
  for (int64_t ma = 0; ma <= 200000; ma += 10) {
    if (comparator_input_uv(ma) > threshold_uv) return ma;
    if (comparator_input_uv(-ma) > threshold_uv) return -ma;
  }
  return 0;
}

static void test_ocp_TripsWithinTenPercentOfItsCurrentThroughTheRealChain(void) {
  const pour_ocp_config_t c = pour_ocp_default_config();
  /* what a healthy board's ADC reads at zero current: 16 x the input's bias */
  const uint16_t offset =
      (uint16_t)((int64_t)POUR_BOARD_VINP_BIAS_UV * POUR_BOARD_PGA_GAIN * 4096 / ((int64_t)POUR_BOARD_ADC_VREF_MV * 1000));
  TEST_ASSERT_INT_WITHIN(2, POUR_BOARD_OFFSET_NOMINAL_COUNTS, offset);
  const int64_t trip = trip_current_ma(pour_ocp_threshold_code(&c, offset));
  /* out of the phase into the low side (the board's sign): within 10 % of the stated 40 A */
  TEST_ASSERT_TRUE(trip < 0);
  TEST_ASSERT_INT32_WITHIN(4000, (int32_t)c.trip_ma, (int32_t)-trip);
  /* the old threshold (the ADC's offset / 9.14 + I x R, no network) tripped at about 126 A */
  const uint16_t old = (uint16_t)(((uint64_t)offset * 1000000u / 9140u + 40000ull * 3000u * 4096u / 3300u / 1000u + 500u) / 1000u);
  TEST_ASSERT_TRUE(-trip_current_ma(old) > 110000);
}

static void test_ocp_init_ArmsTheComparatorsOnDac3(void) {
  const pour_ocp_config_t c = pour_ocp_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_ocp_init(&ocp, comp, dac, &c, offsets));
  TEST_ASSERT_EQUAL_HEX32(3u | (3u << 16), dac[POUR_DAC_MCR]); /* internal, no buffer */
  TEST_ASSERT_EQUAL_HEX32(245u, dac[POUR_DAC_DHR12R1]);
  TEST_ASSERT_EQUAL_HEX32(pour_ocp_threshold_code(&c, 2590u), dac[POUR_DAC_DHR12R2]); /* V and W: the larger */
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
  c.shunt_uohm = 100000u;
  c.trip_ma = 200000u; /* 11.4 V at the comparator: beyond the DAC's 3.3 V */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_ocp_init(&ocp, comp, dac, &c, offsets));
  c = pour_ocp_default_config();
  c.pga_gain = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_ocp_init(&ocp, comp, dac, &c, offsets));
  c = pour_ocp_default_config();
  c.network_milli = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_ocp_init(&ocp, comp, dac, &c, offsets));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_ocp_threshold_code_IsBiasPlusTripCurrentTimesShunt);
  RUN_TEST(test_ocp_TripsWithinTenPercentOfItsCurrentThroughTheRealChain);
  RUN_TEST(test_ocp_init_ArmsTheComparatorsOnDac3);
  RUN_TEST(test_ocp_init_RefusesAnUnreadyDacOrAnUnreachableTrip);
  return UNITY_END();
}
