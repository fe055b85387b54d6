/* SPDX-License-Identifier: MIT */
/* Hardware overcurrent protection: COMP1, COMP2 and COMP4 watch the shunt signals of phases U, V, W at the
 * op-amps' inputs (PA1, PA7, PB0: before the PGA's x16, after the board's network) against thresholds from DAC3
 * (internal, no pin), and their outputs feed TIM1's break input (pwm_tim1.c), which cuts the PWM with no
 * software in the path. The threshold is the input's bias (the measured ADC offset / the PGA's gain) plus the
 * trip current x shunt x the network's attenuation (pour/board_facts.h, ST's project for this board the same).
 * The input rises with current out of the phase into the low side (the ADC reading rises: the board's sign),
 * the direction a short of a phase to the bus drives through a conducting low side. */
#ifndef POUR_OCP_H
#define POUR_OCP_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"
#include "regs.h"

#define POUR_OCP_PERIPHS(P) P(COMP, COMP, 0x40010200) P(DAC3, DAC, 0x50001000)
#define POUR_OCP_REGS(R)                                                                                       \
  R(COMP, C1CSR, 0x00)                                                                                         \
  R(COMP, C2CSR, 0x04)                                                                                         \
  R(COMP, C4CSR, 0x0C)                                                                                         \
  R(DAC, CR, 0x00)                                                                                             \
  R(DAC, DHR12R1, 0x08)                                                                                        \
  R(DAC, DHR12R2, 0x14)                                                                                        \
  R(DAC, SR, 0x34)                                                                                             \
  R(DAC, MCR, 0x3C)
#define POUR_OCP_FIELDS(F)                                                                                     \
  F(COMP, C1CSR, EN, 0, 1)                                                                                     \
  F(COMP, C1CSR, INMSEL, 4, 3)                                                                                 \
  F(COMP, C1CSR, INPSEL, 8, 1)                                                                                 \
  F(COMP, C1CSR, POL, 15, 1)                                                                                   \
  F(COMP, C1CSR, HYST, 16, 3)                                                                                  \
  F(COMP, C1CSR, BLANKSEL, 19, 3)                                                                              \
  F(COMP, C1CSR, VALUE, 30, 1)                                                                                 \
  F(COMP, C2CSR, INMSEL, 4, 3)                                                                                 \
  F(COMP, C4CSR, INMSEL, 4, 3)                                                                                 \
  F(COMP, C4CSR, VALUE, 30, 1)                                                                                 \
  F(DAC, CR, EN1, 0, 1)                                                                                        \
  F(DAC, CR, EN2, 16, 1)                                                                                       \
  F(DAC, DHR12R1, DACCDHR, 0, 12)                                                                             \
  F(DAC, DHR12R2, DACCDHR, 0, 12)                                                                             \
  F(DAC, SR, DAC1RDY, 11, 1)                                                                                   \
  F(DAC, SR, DAC2RDY, 27, 1)                                                                                   \
  F(DAC, MCR, MODE1, 0, 3)                                                                                     \
  F(DAC, MCR, MODE2, 16, 3)
POUR_REGS_DECLARE(OCP);
#define POUR_OCP_COMP_N_REGS (0x1C / 4)
#define POUR_OCP_DAC_N_REGS (0x64 / 4)

typedef struct {
  uint32_t vref_mv;       /* ADC and DAC full scale [mV] */
  uint32_t shunt_uohm;    /* phase shunt [µΩ] */
  uint32_t pga_gain;       /* the op-amp's gain from its input (the comparator's) to the ADC, 2 .. 64 */
  uint32_t network_milli; /* the board's attenuation from the shunt to the op-amp's input [1/1000], 1 .. 1000 */
  uint32_t trip_ma;       /* phase current that trips the break [mA] */
  uint32_t ready_polls;   /* bound of the wait for the DAC's ready flags */
} pour_ocp_config_t;

typedef struct {
  volatile uint32_t *comp, *dac;
  uint16_t threshold[3]; /* DAC codes of phases U, V, W (U: DAC3 CH1; V, W share CH2: the larger bias) */
} pour_ocp_t;

/* B-G431B-ESC1 (pour/board_facts.h): 3.3 V, 3 mΩ, network 0.571, PGA x16, trip at the board's 40 A peak (the
 * software limit is lower). */
pour_ocp_config_t pour_ocp_default_config(void);

/* DAC code for a trip at config->trip_ma from a zero-current ADC reading of offset_counts: offset / PGA gain
 * plus trip x shunt x network, in counts of vref, rounded; 4096 if beyond full scale. */
uint16_t pour_ocp_threshold_code(const pour_ocp_config_t *config, uint16_t offset_counts);

/* Thresholds from the three measured offsets [ADC counts], DAC3 on, the comparators on, non-inverted, their
 * outputs to TIM1's break. POUR_EINVAL for a bad config, a threshold beyond full scale, or a DAC not ready. */
pour_status_t pour_ocp_init(pour_ocp_t *ocp, volatile uint32_t *comp, volatile uint32_t *dac,
                            const pour_ocp_config_t *config, const uint16_t offset_counts[3]);

/* true while any comparator's output is high (the current is above its threshold now). */
bool pour_ocp_tripping(const pour_ocp_t *ocp);

#endif /* POUR_OCP_H */
