/* SPDX-License-Identifier: MIT */
/* TIM1 as the three-phase bridge's PWM: centre-aligned, complementary outputs with dead time, CH4 at the
 * top of the count as the trigger (TRGO2) of the ADCs' injected conversions, so the phase currents are
 * sampled at the centre of the low-side conduction. The break input takes the overcurrent comparators
 * (ocp.c): a trip clears MOE in hardware within the comparator's and the break filter's delay, far less
 * than one PWM period, and the outputs go to their idle levels, all six off (ST's idle levels for this
 * board: a short of a phase to the bus must not meet a conducting low side); the brake holds the axis. Registers through pointers (a register file in tests/board/test_board_pwm.c). */
#ifndef POUR_PWM_TIM1_H
#define POUR_PWM_TIM1_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/fixed.h"
#include "regs.h"

#define POUR_TIM1_PERIPHS(P) P(TIM1, TIM1, 0x40012C00)
#define POUR_TIM1_REGS(R)                                                                                      \
  R(TIM1, CR1, 0x00)                                                                                           \
  R(TIM1, CR2, 0x04)                                                                                           \
  R(TIM1, SR, 0x10)                                                                                            \
  R(TIM1, EGR, 0x14)                                                                                           \
  R(TIM1, CCMR1_OUTPUT, 0x18)                                                                                  \
  R(TIM1, CCMR2_OUTPUT, 0x1C)                                                                                  \
  R(TIM1, CCER, 0x20)                                                                                          \
  R(TIM1, PSC, 0x28)                                                                                           \
  R(TIM1, ARR, 0x2C)                                                                                           \
  R(TIM1, RCR, 0x30)                                                                                           \
  R(TIM1, CCR1, 0x34)                                                                                          \
  R(TIM1, CCR2, 0x38)                                                                                          \
  R(TIM1, CCR3, 0x3C)                                                                                          \
  R(TIM1, CCR4, 0x40)                                                                                          \
  R(TIM1, BDTR, 0x44)                                                                                          \
  R(TIM1, AF1, 0x60)
#define POUR_TIM1_FIELDS(F)                                                                                    \
  F(TIM1, CR1, CEN, 0, 1)                                                                                      \
  F(TIM1, CR1, CMS, 5, 2)                                                                                      \
  F(TIM1, CR1, ARPE, 7, 1)                                                                                     \
  F(TIM1, CR2, OIS1, 8, 1)                                                                                     \
  F(TIM1, CR2, OIS1N, 9, 1)                                                                                    \
  F(TIM1, CR2, OIS2N, 11, 1)                                                                                   \
  F(TIM1, CR2, OIS3N, 13, 1)                                                                                   \
  F(TIM1, CR2, MMS2, 20, 4)                                                                                    \
  F(TIM1, SR, UIF, 0, 1)                                                                                       \
  F(TIM1, SR, BIF, 7, 1)                                                                                       \
  F(TIM1, EGR, UG, 0, 1)                                                                                       \
  F(TIM1, CCMR1_OUTPUT, OC1PE, 3, 1)                                                                           \
  F(TIM1, CCMR1_OUTPUT, OC1M, 4, 3)                                                                            \
  F(TIM1, CCMR1_OUTPUT, OC2PE, 11, 1)                                                                          \
  F(TIM1, CCMR1_OUTPUT, OC2M, 12, 3)                                                                           \
  F(TIM1, CCMR2_OUTPUT, OC3PE, 3, 1)                                                                           \
  F(TIM1, CCMR2_OUTPUT, OC3M, 4, 3)                                                                            \
  F(TIM1, CCMR2_OUTPUT, OC4PE, 11, 1)                                                                          \
  F(TIM1, CCMR2_OUTPUT, OC4M, 12, 3)                                                                           \
  F(TIM1, CCER, CC1E, 0, 1)                                                                                    \
  F(TIM1, CCER, CC1NE, 2, 1)                                                                                   \
  F(TIM1, CCER, CC2E, 4, 1)                                                                                    \
  F(TIM1, CCER, CC2NE, 6, 1)                                                                                   \
  F(TIM1, CCER, CC3E, 8, 1)                                                                                    \
  F(TIM1, CCER, CC3NE, 10, 1)                                                                                  \
  F(TIM1, CCER, CC4E, 12, 1)                                                                                   \
  F(TIM1, PSC, PSC, 0, 16)                                                                                     \
  F(TIM1, ARR, ARR, 0, 20)                                                                                     \
  F(TIM1, RCR, REP, 0, 16)                                                                                     \
  F(TIM1, CCR1, CCR, 0, 20)                                                                                    \
  F(TIM1, CCR4, CCR, 0, 20)                                                                                    \
  F(TIM1, BDTR, DTG, 0, 8)                                                                                     \
  F(TIM1, BDTR, OSSI, 10, 1)                                                                                   \
  F(TIM1, BDTR, OSSR, 11, 1)                                                                                   \
  F(TIM1, BDTR, BKE, 12, 1)                                                                                    \
  F(TIM1, BDTR, BKP, 13, 1)                                                                                    \
  F(TIM1, BDTR, AOE, 14, 1)                                                                                    \
  F(TIM1, BDTR, MOE, 15, 1)                                                                                    \
  F(TIM1, BDTR, BKF, 16, 4)                                                                                    \
  F(TIM1, AF1, BKINE, 0, 1)                                                                                    \
  F(TIM1, AF1, BKCMP1E, 1, 1)                                                                                  \
  F(TIM1, AF1, BKCMP2E, 2, 1)                                                                                  \
  F(TIM1, AF1, BKCMP4E, 4, 1)
POUR_REGS_DECLARE(TIM1);
#define POUR_TIM1_N_REGS (0x68 / 4) /* the register file a host test provides [words] */

typedef struct {
  uint32_t timer_clock_hz; /* TIM1's clock (PCLK2 x 1) [Hz] */
  uint32_t pwm_hz;         /* PWM and current-loop rate [Hz], 16,000 .. 40,000 */
  uint32_t deadtime_ns;    /* each leg's dead time [ns], 1 .. the longest DTG gives (RM0440: 2 ranges here) */
  uint8_t break_filter;    /* BKF: 0 = none; N samples at f_DTS (RM0440 table), 0 .. 15 */
} pour_pwm_config_t;

typedef struct {
  volatile uint32_t *regs;
  uint16_t period; /* ARR: counts from the bottom to the top of the centre-aligned count */
  bool shorted;    /* the low sides shorted by pour_pwm_short_low_sides, until a compare or enable changes it */
} pour_pwm_t;

/* B-G431B-ESC1: 170 MHz, 20 kHz, 800 ns dead time (pour/board_facts.h), break filter 6 samples at f_DTS / 4. */
pour_pwm_config_t pour_pwm_default_config(void);

/* The dead-time generator's DTG code for deadtime_ns at timer_clock_hz (rounded up: never shorter); -1 if
 * it is 0 or longer than the two ranges used here (127 and 2 x (64 .. 127) clock periods) give. */
int32_t pour_pwm_deadtime_code(uint32_t timer_clock_hz, uint32_t deadtime_ns);

/* Configures TIM1 and starts its count with all six switches off. POUR_EINVAL for a bad config. */
pour_status_t pour_pwm_init(pour_pwm_t *pwm, volatile uint32_t *regs, const pour_pwm_config_t *config);

/* Next period's compares, 0 .. period each (0: the low side on all period); larger values are clamped. */
void pour_pwm_set_compares(pour_pwm_t *pwm, const uint16_t compare[3]);

/* true: the gates follow the compares; false: all six switches off. After a break neither: the idle levels
 * (all six off) hold until pour_pwm_clear_break. */
void pour_pwm_enable(pour_pwm_t *pwm, bool on);

/* All three low sides on (compares 0) while MOE is set: the motor's phases shorted (a software fault's
 * damping). After a break MOE stays clear and the bridge stays off. The update event that applies it at once
 * (EGR.UG) is generated on entering the short only: UG also re-initialises the counter (RM0440, TIM1_EGR;
 * the stm32g4 SVD's UG field), so one on every call of a faulted drive's 20 kHz interrupt restarted the PWM
 * period, and the ADC trigger with it, before it ended (the virtual board saw the interrupt at 31.95 kHz). */
void pour_pwm_short_low_sides(pour_pwm_t *pwm);

/* true once the break input has fired (SR.BIF), until pour_pwm_clear_break. */
bool pour_pwm_break_fired(const pour_pwm_t *pwm);

/* Clears a break (ClearErrors): the flag, and MOE set again with all six switches off. If the comparators
 * still trip, the hardware keeps MOE clear and the flag comes back. */
void pour_pwm_clear_break(pour_pwm_t *pwm);

/* true while the gates follow the compares (MOE set and the bridge's channels enabled). */
bool pour_pwm_enabled(const pour_pwm_t *pwm);

#endif /* POUR_PWM_TIM1_H */
