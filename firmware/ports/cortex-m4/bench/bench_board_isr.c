/* SPDX-License-Identifier: MIT */
/* Instructions per current-loop interrupt as the board runs it (pour_board_drive_isr: the period's sample
 * from ADC1/ADC2 and TIM4 through hal_drive_g4, pour_drive_isr, the compares and gates back to TIM1) on QEMU
 * mps2-an386 under -icount shift=0, the peripherals' registers in plain memory, each call timed on its own
 * over samples that keep the loop running. Prints figures; fails only when the drive never runs. */
#include <stdio.h>

#include "board_drive.h"
#include "encoder_tim4.h"
#include "hal_brake.h"
#include "hal_drive.h"
#include "hal_drive_g4.h"
#include "hal_power.h"
#include "icount.h"
#include "pour/board_facts.h"

#define N_CALLS 20000u

/* The board's analog chain (pour/board_facts.h): the amplifiers' bias at zero current, the sign of a phase
 * current against its count, the bus at 24 V through its divider. */
#define BIAS POUR_BOARD_OFFSET_NOMINAL_COUNTS
#define SIGN POUR_BOARD_CURRENT_SIGN
#define VBUS_24V                                                                                             \
  ((uint32_t)((24000ull * 4096u * 1000u + (uint64_t)POUR_BOARD_ADC_VREF_MV * POUR_BOARD_VBUS_DIVIDER_MILLI / 2u) / \
              ((uint64_t)POUR_BOARD_ADC_VREF_MV * POUR_BOARD_VBUS_DIVIDER_MILLI)))

static uint32_t tim1[POUR_TIM1_N_REGS], tim4[POUR_TIM4_N_REGS], adc1[POUR_ADC_N_REGS], adc2[POUR_ADC_N_REGS];

/* The board's own parts, not timed here. */
pour_status_t pour_hal_drive_init(void) { return POUR_OK; }
pour_status_t pour_hal_drive_arm_overcurrent(const uint16_t offset_counts[3]) {
  (void)offset_counts;
  return POUR_OK;
}
void pour_hal_drive_mask(bool masked) { (void)masked; }
void pour_hal_brake_init(void) {}
void pour_hal_brake_set(bool engage) { (void)engage; }
bool pour_hal_brake_engaged(void) { return true; }
void pour_hal_power_init(void) {}
void pour_hal_power_set(bool on) { (void)on; }
bool pour_hal_power_on(void) { return false; }

/* Period i's conversions: phase currents within ±3 A summing to zero (a sweep that visits each pair of
 * values), the bus at 24 V, the encoder turning. */
static void convert(uint32_t i) {
  const int32_t ia = (int32_t)((i * 37u) % 201u) - 100, ib = (int32_t)((i * 91u + 50u) % 201u) - 100;
  adc1[POUR_ADC_JDR1] = (uint32_t)(BIAS + SIGN * ia);
  adc2[POUR_ADC_JDR1] = (uint32_t)(BIAS + SIGN * ib);
  adc1[POUR_ADC_JDR2] = (uint32_t)(BIAS - SIGN * (ia + ib));
  adc1[POUR_ADC_JDR3] = VBUS_24V;
  adc1[POUR_ADC_JDR4] = 1309u;
  tim4[POUR_TIM4_CNT] = (i * 7919u) & 0xFFFFu;
  adc1[POUR_ADC_ISR] = (1u << 5) | (1u << 6); /* JEOC, JEOS */
}

int main(void) {
  const uint32_t insn_per_kilotick = icount_start();
  pour_pwm_t pwm;
  const pour_pwm_config_t pc = pour_pwm_default_config();
  const pour_adc_t adc = {adc1, adc2, NULL, 10u};
  pour_drive_config_t dc = pour_drive_default_config();
  dc.phase_loss_ms = 1000; /* the synthetic currents do not follow the loop: keep it running */
  if (pour_pwm_init(&pwm, tim1, &pc) != POUR_OK) {
    printf("pour_pwm_init failed\n");
    return 1;
  }
  pour_hal_drive_attach(&pwm, &adc, tim4, NULL);
  if (pour_board_drive_init(&dc, 20000, true) != POUR_OK) {
    printf("pour_board_drive_init failed\n");
    return 1;
  }
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) {
    adc1[POUR_ADC_JDR1] = adc2[POUR_ADC_JDR1] = adc1[POUR_ADC_JDR2] = BIAS;
    adc1[POUR_ADC_JDR3] = VBUS_24V;
    adc1[POUR_ADC_ISR] = (1u << 5) | (1u << 6);
    pour_board_drive_isr();
  }
  uint32_t empty = 0u;
  for (uint32_t i = 0; i < 64u; ++i) {
    const uint32_t t0 = now();
    __asm volatile("" ::: "memory");
    empty += elapsed(t0, now());
  }
  empty /= 64u;
  uint32_t worst = 0u, n = 0u;
  uint64_t sum = 0u;
  for (uint32_t i = 0; i < N_CALLS && pour_board_drive_state()->state == POUR_DRIVE_RUN; ++i) {
    convert(i);
    const uint32_t t0 = now();
    pour_board_drive_isr();
    const uint32_t t = elapsed(t0, now()) - empty;
    worst = t > worst ? t : worst;
    sum += t;
    ++n;
  }
  if (n == 0u) { /* nothing measured: a drive that never ran is no figure */
    printf("error: the drive never ran (state %d, faults 0x%04x)\n", (int)pour_board_drive_state()->state,
           (unsigned)pour_board_drive_state()->faults);
    return 1;
  }
  printf("board current-loop interrupt (pour_board_drive_isr: sample, pour_drive_isr, compares): worst %u "
         "instructions, average %u (%u calls, faults 0x%04x)\n",
         (unsigned)(worst * insn_per_kilotick / 1000u), (unsigned)(sum * insn_per_kilotick / 1000u / (n ? n : 1u)),
         (unsigned)n, (unsigned)pour_board_drive_state()->faults);
  return 0;
}
