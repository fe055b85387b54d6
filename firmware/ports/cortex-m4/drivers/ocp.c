/* SPDX-License-Identifier: MIT */
#include "ocp.h"

#include <stddef.h>

#include "pour/board_facts.h"

#define INMSEL_DAC3 4u     /* COMP1: DAC3 CH1; COMP2, COMP4: DAC3 CH2 (RM0440 comparator inputs) */
#define HYST_10MV 1u
#define DAC_MODE_INTERNAL 3u /* normal mode, connected to on-chip peripherals only, buffer off */

pour_ocp_config_t pour_ocp_default_config(void) {
  pour_ocp_config_t c;
  c.vref_mv = POUR_BOARD_ADC_VREF_MV;
  c.shunt_uohm = POUR_BOARD_SHUNT_UOHM;
  c.pga_gain = POUR_BOARD_PGA_GAIN;
  c.network_milli = POUR_BOARD_INPUT_NETWORK_MILLI;
  c.trip_ma = POUR_BOARD_BOARD_PEAK_MA;
  c.ready_polls = 10000u;
  return c;
}

uint16_t pour_ocp_threshold_code(const pour_ocp_config_t *config, uint16_t offset_counts) {
  /* The comparator sees the op-amp's input: the ADC's offset / the PGA's gain, plus I x R x the network. In
   * 1/4096 of vref, x 1e6: bias = offset x 1e6 / gain; trip = I[mA] x R[µΩ] x net[1/1000] x 1e-12 V x 4096 / vref
   * (the config's bounds: < 2^18 · 2^17 · 2^10 · 2^12 = 2^57). */
  const uint64_t bias = (uint64_t)offset_counts * 1000000u / config->pga_gain;
  const uint64_t trip =
      (uint64_t)config->trip_ma * config->shunt_uohm * config->network_milli * 4096u / config->vref_mv / 1000u;
  const uint64_t code = (bias + trip + 500000u) / 1000000u;
  return code > 4095u ? 4096u : (uint16_t)code;
}

pour_status_t pour_ocp_init(pour_ocp_t *ocp, volatile uint32_t *comp, volatile uint32_t *dac,
                            const pour_ocp_config_t *config, const uint16_t offset_counts[3]) {
  if (ocp == NULL || comp == NULL || dac == NULL || config == NULL || offset_counts == NULL ||
      config->vref_mv == 0u || config->pga_gain < 2u || config->pga_gain > 64u || config->network_milli == 0u ||
      config->network_milli > 1000u || config->trip_ma == 0u || config->trip_ma > 200000u || config->shunt_uohm == 0u ||
      config->shunt_uohm > 100000u || config->ready_polls == 0u) {
    return POUR_EINVAL;
  }
  for (unsigned i = 0; i < 3u; ++i) {
    ocp->threshold[i] = pour_ocp_threshold_code(config, offset_counts[i]);
    if (ocp->threshold[i] > 4095u) {
      return POUR_EINVAL;
    }
  }
  ocp->comp = comp;
  ocp->dac = dac;
  const uint16_t vw = ocp->threshold[1] > ocp->threshold[2] ? ocp->threshold[1] : ocp->threshold[2];
  dac[POUR_DAC_MCR] = POUR_VAL(DAC, MCR, MODE1, DAC_MODE_INTERNAL) | POUR_VAL(DAC, MCR, MODE2, DAC_MODE_INTERNAL);
  dac[POUR_DAC_DHR12R1] = POUR_VAL(DAC, DHR12R1, DACCDHR, ocp->threshold[0]);
  dac[POUR_DAC_DHR12R2] = POUR_VAL(DAC, DHR12R2, DACCDHR, vw);
  dac[POUR_DAC_CR] = POUR_MSK(DAC, CR, EN1) | POUR_MSK(DAC, CR, EN2);
  const uint32_t ready = POUR_MSK(DAC, SR, DAC1RDY) | POUR_MSK(DAC, SR, DAC2RDY);
  if (pour_regs_wait(&dac[POUR_DAC_SR], ready, ready, config->ready_polls) != 0) {
    return POUR_EINVAL;
  }
  /* INP: VINP0 pins (INPSEL 0: COMP1 PA1, COMP2 PA7, COMP4 PB0); output high above the threshold. */
  const uint32_t csr = POUR_MSK(COMP, C1CSR, EN) | POUR_VAL(COMP, C1CSR, INMSEL, INMSEL_DAC3) |
                       POUR_VAL(COMP, C1CSR, HYST, HYST_10MV);
  comp[POUR_COMP_C1CSR] = csr;
  comp[POUR_COMP_C2CSR] = csr;
  comp[POUR_COMP_C4CSR] = csr;
  return POUR_OK;
}

bool pour_ocp_tripping(const pour_ocp_t *ocp) {
  const uint32_t v = POUR_MSK(COMP, C1CSR, VALUE);
  return ((ocp->comp[POUR_COMP_C1CSR] | ocp->comp[POUR_COMP_C2CSR] | ocp->comp[POUR_COMP_C4CSR]) & v) != 0u;
}
