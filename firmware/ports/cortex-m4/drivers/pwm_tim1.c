/* SPDX-License-Identifier: MIT */
#include "pwm_tim1.h"

#include <stddef.h>

#define OCM_PWM1 6u        /* OCxREF high while CNT < CCRx */
#define CMS_CENTRE1 1u     /* centre-aligned; compare flags set counting down */
#define MMS2_OC4REF 7u     /* TRGO2 = OC4REF: rises as the count leaves the top */
#define BKF_MAX 15u
#define CCER_BRIDGE                                                                                           \
  (POUR_MSK(TIM1, CCER, CC1E) | POUR_MSK(TIM1, CCER, CC1NE) | POUR_MSK(TIM1, CCER, CC2E) |                   \
   POUR_MSK(TIM1, CCER, CC2NE) | POUR_MSK(TIM1, CCER, CC3E) | POUR_MSK(TIM1, CCER, CC3NE))

pour_pwm_config_t pour_pwm_default_config(void) {
  pour_pwm_config_t c;
  c.timer_clock_hz = 170000000u;
  c.pwm_hz = 20000u;
  c.deadtime_ns = 800u;
  c.break_filter = 6u; /* f_DTS / 4, N = 6: 141 ns, the length of ST's filter for this board (BKF 4 at CKD / 2) */
  return c;
}

int32_t pour_pwm_deadtime_code(uint32_t timer_clock_hz, uint32_t deadtime_ns) {
  if (deadtime_ns == 0u || timer_clock_hz == 0u) {
    return -1;
  }
  /* Clock periods, rounded up. */
  const uint64_t ticks = ((uint64_t)deadtime_ns * timer_clock_hz + 999999999u) / 1000000000u;
  if (ticks <= 127u) {
    return (int32_t)ticks; /* DTG[7] = 0: DTG x t_DTS */
  }
  const uint64_t pairs = (ticks + 1u) / 2u; /* DTG[7:6] = 10: (64 + DTG[5:0]) x 2 t_DTS */
  if (pairs <= 127u) {
    return (int32_t)(0x80u | (uint32_t)(pairs - 64u));
  }
  return -1;
}

pour_status_t pour_pwm_init(pour_pwm_t *pwm, volatile uint32_t *regs, const pour_pwm_config_t *config) {
  if (pwm == NULL || regs == NULL || config == NULL || config->pwm_hz < 16000u || config->pwm_hz > 40000u ||
      config->break_filter > BKF_MAX) {
    return POUR_EINVAL;
  }
  const uint32_t period = config->timer_clock_hz / (2u * config->pwm_hz);
  const int32_t dtg = pour_pwm_deadtime_code(config->timer_clock_hz, config->deadtime_ns);
  /* The dead time must leave most of the period: at most 5 % of it. */
  if (period < 100u || period > 0xFFFFu || dtg < 0 ||
      (uint64_t)config->deadtime_ns * config->pwm_hz * 20u > 1000000000u) {
    return POUR_EINVAL;
  }
  pwm->regs = regs;
  pwm->shorted = false;
  pwm->period = (uint16_t)period;
  volatile uint32_t *r = regs;
  r[POUR_TIM1_BDTR] = 0u; /* MOE off first */
  r[POUR_TIM1_CR1] = POUR_VAL(TIM1, CR1, CMS, CMS_CENTRE1) | POUR_MSK(TIM1, CR1, ARPE);
  r[POUR_TIM1_PSC] = 0u;
  r[POUR_TIM1_ARR] = period;
  r[POUR_TIM1_RCR] = 0u;
  r[POUR_TIM1_CCR1] = 0u;
  r[POUR_TIM1_CCR2] = 0u;
  r[POUR_TIM1_CCR3] = 0u;
  r[POUR_TIM1_CCR4] = period - 1u; /* OC4REF falls at the top, rises leaving it: the ADC trigger */
  r[POUR_TIM1_CCMR1_OUTPUT] = POUR_VAL(TIM1, CCMR1_OUTPUT, OC1M, OCM_PWM1) | POUR_MSK(TIM1, CCMR1_OUTPUT, OC1PE) |
                              POUR_VAL(TIM1, CCMR1_OUTPUT, OC2M, OCM_PWM1) | POUR_MSK(TIM1, CCMR1_OUTPUT, OC2PE);
  r[POUR_TIM1_CCMR2_OUTPUT] = POUR_VAL(TIM1, CCMR2_OUTPUT, OC3M, OCM_PWM1) | POUR_MSK(TIM1, CCMR2_OUTPUT, OC3PE) |
                              POUR_VAL(TIM1, CCMR2_OUTPUT, OC4M, OCM_PWM1) | POUR_MSK(TIM1, CCMR2_OUTPUT, OC4PE);
  /* Idle levels (MOE clear after a break, OSSI): all six off, OISx = OISxN = 0, as ST sets them for this board
   * (pour/board_facts.h): with a failed high side or a phase shorted to the bus, low sides switched on by the
   * hardware would short the bus itself. */
  r[POUR_TIM1_CR2] = POUR_VAL(TIM1, CR2, MMS2, MMS2_OC4REF);
  r[POUR_TIM1_CCER] = 0u; /* with MOE and OSSR set: all six at their inactive level, off */
  /* The comparators of phases U, V, W (COMP1, COMP2, COMP4) into the break, active high; no automatic
   * restart (AOE clear): a trip stays until ClearErrors. */
  r[POUR_TIM1_AF1] = POUR_MSK(TIM1, AF1, BKCMP1E) | POUR_MSK(TIM1, AF1, BKCMP2E) | POUR_MSK(TIM1, AF1, BKCMP4E);
  r[POUR_TIM1_BDTR] = POUR_VAL(TIM1, BDTR, DTG, (uint32_t)dtg) | POUR_MSK(TIM1, BDTR, OSSI) |
                      POUR_MSK(TIM1, BDTR, OSSR) | POUR_MSK(TIM1, BDTR, BKE) | POUR_MSK(TIM1, BDTR, BKP) |
                      POUR_VAL(TIM1, BDTR, BKF, config->break_filter) | POUR_MSK(TIM1, BDTR, MOE);
  r[POUR_TIM1_EGR] = POUR_MSK(TIM1, EGR, UG); /* load the preloaded values */
  r[POUR_TIM1_SR] = 0u;
  r[POUR_TIM1_CR1] |= POUR_MSK(TIM1, CR1, CEN);
  return POUR_OK;
}

void pour_pwm_set_compares(pour_pwm_t *pwm, const uint16_t compare[3]) {
  volatile uint32_t *r = pwm->regs;
  pwm->shorted = false;
  r[POUR_TIM1_CCR1] = compare[0] > pwm->period ? pwm->period : compare[0];
  r[POUR_TIM1_CCR2] = compare[1] > pwm->period ? pwm->period : compare[1];
  r[POUR_TIM1_CCR3] = compare[2] > pwm->period ? pwm->period : compare[2];
}

/* Off is the channels disabled under a set MOE (OSSR: their inactive level), not MOE cleared: a cleared
 * MOE means the break, whose idle levels are all off until the break is cleared. */
void pour_pwm_enable(pour_pwm_t *pwm, bool on) {
  pwm->shorted = false;
  pwm->regs[POUR_TIM1_CCER] = on ? CCER_BRIDGE : 0u;
}

void pour_pwm_short_low_sides(pour_pwm_t *pwm) {
  if (pwm->shorted) {
    return; /* already: no second update event (it would restart the counter) */
  }
  const uint16_t zero[3] = {0u, 0u, 0u};
  pour_pwm_set_compares(pwm, zero);
  pwm->regs[POUR_TIM1_EGR] = POUR_MSK(TIM1, EGR, UG); /* now, not at the next period */
  pour_pwm_enable(pwm, true); /* after a break MOE stays clear: the bridge stays off, the brake holds */
  pwm->shorted = true;
}

bool pour_pwm_break_fired(const pour_pwm_t *pwm) { return (pwm->regs[POUR_TIM1_SR] & POUR_MSK(TIM1, SR, BIF)) != 0u; }

void pour_pwm_clear_break(pour_pwm_t *pwm) {
  volatile uint32_t *r = pwm->regs;
  pwm->shorted = false;
  r[POUR_TIM1_CCER] = 0u;
  r[POUR_TIM1_SR] = ~POUR_MSK(TIM1, SR, BIF); /* rc_w0 */
  r[POUR_TIM1_BDTR] |= POUR_MSK(TIM1, BDTR, MOE); /* the hardware keeps it clear while the break is active */
}

bool pour_pwm_enabled(const pour_pwm_t *pwm) {
  return (pwm->regs[POUR_TIM1_BDTR] & POUR_MSK(TIM1, BDTR, MOE)) != 0u && pwm->regs[POUR_TIM1_CCER] == CCER_BRIDGE;
}
