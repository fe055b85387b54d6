/* SPDX-License-Identifier: MIT */
/* The current loop's interrupt against register files in plain memory: board_drive over hal_drive_g4 over
 * the TIM1, ADC1/ADC2 and TIM4 drivers, as on the chip. Each period's end of sequence (ADC1 JEOS) has the
 * interrupt read the injected data registers (JDR1..4 of ADC1, JDR1 of ADC2) and TIM4's count, acknowledge
 * the flags and write the drive's compares into CCR1..3; no sample, no write; the gates stay off while the
 * offsets are measured; a tripped loop leaves the compares at 0 with the bridge on (the low sides short the
 * phases); a ClearErrors of a broken amplifier measures the offsets again with the gates off, and clears
 * the fault only if they pass. The board's own parts (the NVIC, the comparators' thresholds, the brake and
 * power lines) are answered here. */
#include <string.h>

#include "board_drive.h"
#include "brake_power_lines.h"
#include "encoder_tim4.h"
#include "hal_drive.h"
#include "hal_drive_g4.h"
#include "pour/control.h"
#include "unity.h"

static uint32_t tim1[POUR_TIM1_N_REGS], tim4[POUR_TIM4_N_REGS], adc1[POUR_ADC_N_REGS], adc2[POUR_ADC_N_REGS];
static uint32_t comp[POUR_OCP_COMP_N_REGS];
static pour_ocp_t ocp;

pour_status_t pour_hal_drive_init(void) { return POUR_OK; }
static int armed; /* the cut armed on these offsets, this many times */
static uint16_t armed_on[3];
pour_status_t pour_hal_drive_arm_overcurrent(const uint16_t offset_counts[3]) {
  memcpy(armed_on, offset_counts, sizeof armed_on);
  armed++;
  return POUR_OK;
}
void pour_hal_drive_mask(bool masked) { (void)masked; }

#define CCER_BRIDGE 0x555u /* CC1E/NE, CC2E/NE, CC3E/NE */
#define JEOC_JEOS ((1u << 5) | (1u << 6))

void setUp(void) {
  memset(tim1, 0, sizeof tim1);
  memset(tim4, 0, sizeof tim4);
  memset(adc1, 0, sizeof adc1);
  memset(adc2, 0, sizeof adc2);
  memset(comp, 0, sizeof comp);
  ocp.comp = comp;
  pour_pwm_t pwm;
  const pour_pwm_config_t pc = pour_pwm_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_pwm_init(&pwm, tim1, &pc));
  const pour_adc_t adc = {adc1, adc2, NULL, 10u};
  pour_hal_drive_attach(&pwm, &adc, tim4, &ocp);
  const pour_drive_config_t dc = pour_drive_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_board_drive_init(&dc, 20000, true));
  armed = 0;
}

void tearDown(void) {}

/* One period's conversions done: U, V, W, the bus, the NTC in their data registers; the encoder's count. */
static void convert(uint16_t u, uint16_t v, uint16_t w, uint16_t count) {
  adc1[POUR_ADC_JDR1] = u;
  adc2[POUR_ADC_JDR1] = v;
  adc1[POUR_ADC_JDR2] = w;
  adc1[POUR_ADC_JDR3] = 2867u; /* 24 V through the board's 10.389 divider */
  adc1[POUR_ADC_JDR4] = 1309u; /* 25 °C */
  tim4[POUR_TIM4_CNT] = count;
  adc1[POUR_ADC_ISR] = JEOC_JEOS;
}

/* The interrupt; the flags' acknowledgement (rc_w1) is read back and the flags cleared as the hardware would. */
static void isr_acknowledged(void) {
  adc1[POUR_ADC_ISR] |= 1u << 0; /* ADRDY stays: the acknowledgement writes only JEOC and JEOS */
  pour_board_drive_isr();
  TEST_ASSERT_EQUAL_HEX32(JEOC_JEOS, adc1[POUR_ADC_ISR]);
  TEST_ASSERT_EQUAL_HEX32(JEOC_JEOS, adc2[POUR_ADC_ISR]);
  adc1[POUR_ADC_ISR] = 0u;
  adc2[POUR_ADC_ISR] = 0u;
}

static void calibrate(void) {
  for (int k = 0; k < POUR_CURRENT_SENSE_CAL_SAMPLES; ++k) {
    convert(2553u, 2555u, 2551u, 0u);
    isr_acknowledged();
    TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCER]); /* the gates off while the offsets are measured */
  }
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, pour_board_drive_state()->state);
}

static void test_drive_isr_WithoutTheEndOfSequenceNothingIsRead(void) {
  tim1[POUR_TIM1_CCR1] = 1234u;
  pour_board_drive_isr();
  TEST_ASSERT_EQUAL_HEX32(1234u, tim1[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_HEX32(0u, adc1[POUR_ADC_ISR]);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_CALIBRATING, pour_board_drive_state()->state);
}

static void test_drive_isr_ReadsTheDataRegistersAndWritesTheCompares(void) {
  calibrate();
  const uint16_t offsets[3] = {2553u, 2555u, 2551u};
  TEST_ASSERT_EQUAL_UINT16_ARRAY(offsets, pour_board_drive_state()->sense.offset, 3);
  /* At zero current and no reference the bridge runs at half duty: each compare mid-period. */
  convert(2553u, 2555u, 2551u, 100u);
  isr_acknowledged();
  const pour_drive_output_t *o = pour_board_drive_output();
  TEST_ASSERT_EQUAL_HEX32(CCER_BRIDGE, tim1[POUR_TIM1_CCER]);
  for (int k = 0; k < 3; ++k) {
    TEST_ASSERT_EQUAL_UINT32(o->compare[k], tim1[POUR_TIM1_CCR1 + k]);
    TEST_ASSERT_UINT32_WITHIN(50u, 2125u, tim1[POUR_TIM1_CCR1 + k]);
  }
  TEST_ASSERT_EQUAL_UINT16(100u, pour_board_drive_state()->last_encoder); /* TIM4's count reached the loop */
  /* U 200 counts above its offset, V and W sharing the return: the loop answers, its compares follow. */
  for (int n = 0; n < 5; ++n) {
    convert(2753u, 2455u, 2451u, 100u);
    isr_acknowledged();
  }
  TEST_ASSERT_TRUE(o->id != 0 || o->iq != 0);
  for (int k = 0; k < 3; ++k) {
    TEST_ASSERT_EQUAL_UINT32(o->compare[k], tim1[POUR_TIM1_CCR1 + k]);
  }
  TEST_ASSERT_TRUE(tim1[POUR_TIM1_CCR1] != tim1[POUR_TIM1_CCR2]);
}

static void test_drive_isr_ATrippedLoopShortsThePhasesThroughTheCompares(void) {
  calibrate();
  convert(4095u, 2555u, 0u, 0u); /* beyond the 45 A software limit on U and W */
  tim1[POUR_TIM1_EGR] = 0u;
  isr_acknowledged();
  TEST_ASSERT_BITS_HIGH(POUR_DRIVE_FAULT_OVERCURRENT, pour_board_drive_state()->faults);
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCR2]);
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCR3]);
  TEST_ASSERT_EQUAL_HEX32(CCER_BRIDGE, tim1[POUR_TIM1_CCER]); /* the low sides on, all period */
  TEST_ASSERT_EQUAL_HEX32(1u, tim1[POUR_TIM1_EGR]);           /* now, not at the next update */
  convert(2553u, 2555u, 2551u, 0u); /* the current gone: still shorted, latched */
  isr_acknowledged();
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, pour_board_drive_state()->state);
}

/* The comparators' break (SR.BIF, MOE cleared by the hardware): a clear while a comparator's output is high
 * leaves it fired; once every output is low, the flag clears and MOE is set with all six switches off. */
static void test_drive_isr_TheBreakClearsOnlyOnceTheComparatorsAreLow(void) {
  calibrate();
  tim1[POUR_TIM1_SR] |= 1u << 7;           /* BIF */
  tim1[POUR_TIM1_BDTR] &= ~(1u << 15);     /* MOE */
  comp[POUR_COMP_C4CSR] |= 1u << 30;       /* phase W still above its threshold */
  TEST_ASSERT_TRUE(pour_hal_drive_overcurrent_tripped());
  pour_hal_drive_clear_overcurrent();
  TEST_ASSERT_TRUE(pour_hal_drive_overcurrent_tripped());
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_BDTR] & (1u << 15));
  comp[POUR_COMP_C4CSR] &= ~(1u << 30);
  pour_hal_drive_clear_overcurrent();
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_SR] & (1u << 7));
  TEST_ASSERT_EQUAL_HEX32(1u << 15, tim1[POUR_TIM1_BDTR] & (1u << 15));
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCER]); /* all six off until the loop drives them again */
}

/* The board's 1 kHz tick around the core (no sensor samples: nothing to run), with a ClearErrors if asked. */
static pour_control_t ctl;
static void board_tick(bool clear) {
  pour_control_input_t in;
  memset(&in, 0, sizeof in);
  in.clear_faults = clear;
  pour_control_output_t out;
  pour_board_drive_tick(&ctl, &in, &out);
}

/* ms milliseconds of 20 periods, phase U's amplifier at u counts (2553: the board's bias), a tick after each
 * with a ClearErrors at the first if asked; counts the periods with the gates on while the drive measured
 * its offsets, and the ticks with the brake released. */
static int gates_on_measuring, released;
static void run_ms(int ms, uint16_t u, bool clear_first) {
  for (int t = 0; t < ms; ++t) {
    for (int k = 0; k < 20; ++k) {
      convert(u, 2555u, 2551u, 0u);
      isr_acknowledged();
      const bool measuring = pour_board_drive_state()->state == POUR_DRIVE_CALIBRATING;
      gates_on_measuring += measuring && tim1[POUR_TIM1_CCER] != 0u ? 1 : 0;
    }
    board_tick(clear_first && t == 0);
    released += brake_line ? 0 : 1;
  }
}

/* A broken amplifier at start-up (U 400 counts off its bias, beyond the 100 accepted): CURRENT_OFFSET, the
 * phases shorted. A ClearErrors measures the offsets again with the gates off and the brake engaged. */
static void broken_amplifier_cleared(void) {
  const pour_control_config_t cc = pour_control_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &cc, 1u));
  gates_on_measuring = released = 0;
  run_ms(20, 2953u, false);
  const pour_drive_t *drv = pour_board_drive_state();
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv->state);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, pour_board_drive_faults());
  TEST_ASSERT_EQUAL_HEX32(CCER_BRIDGE, tim1[POUR_TIM1_CCER]); /* shorted */
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_INT(0, armed);
  run_ms(1, 2953u, true); /* the board hands the clear to the drive before the core's step, in the same tick */
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_CALIBRATING, drv->state);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, drv->faults); /* latched until they pass */
}

static void test_drive_isr_AClearMeasuresTheOffsetsAgainAndClearsThemInRange(void) {
  broken_amplifier_cleared();
  run_ms(20, 2553u, false); /* the amplifier reads its bias again: 256 periods, 12.8 ms */
  const pour_drive_t *drv = pour_board_drive_state();
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv->state);
  TEST_ASSERT_EQUAL_HEX16(0u, pour_board_drive_faults());
  const uint16_t offsets[3] = {2553u, 2555u, 2551u};
  TEST_ASSERT_EQUAL_UINT16_ARRAY(offsets, drv->sense.offset, 3);
  TEST_ASSERT_EQUAL_INT(1, armed); /* the cut armed on the new offsets */
  TEST_ASSERT_EQUAL_UINT16_ARRAY(offsets, armed_on, 3);
  TEST_ASSERT_EQUAL_INT(0, gates_on_measuring);
  TEST_ASSERT_EQUAL_INT(0, released);                       /* the core, latched, keeps the brake until a clear */
  TEST_ASSERT_EQUAL_HEX32(CCER_BRIDGE, tim1[POUR_TIM1_CCER]); /* the loop runs at zero current */
}

static void test_drive_isr_AClearWithTheAmplifierStillBrokenKeepsItLatched(void) {
  broken_amplifier_cleared();
  run_ms(20, 2953u, false);
  const pour_drive_t *drv = pour_board_drive_state();
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv->state);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, pour_board_drive_faults());
  TEST_ASSERT_EQUAL_HEX32(CCER_BRIDGE, tim1[POUR_TIM1_CCER]); /* shorted again */
  TEST_ASSERT_EQUAL_HEX32(0u, tim1[POUR_TIM1_CCR1]);
  TEST_ASSERT_EQUAL_INT(0, armed);
  TEST_ASSERT_EQUAL_INT(0, gates_on_measuring);
  TEST_ASSERT_EQUAL_INT(0, released);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_drive_isr_WithoutTheEndOfSequenceNothingIsRead);
  RUN_TEST(test_drive_isr_ReadsTheDataRegistersAndWritesTheCompares);
  RUN_TEST(test_drive_isr_ATrippedLoopShortsThePhasesThroughTheCompares);
  RUN_TEST(test_drive_isr_TheBreakClearsOnlyOnceTheComparatorsAreLow);
  RUN_TEST(test_drive_isr_AClearMeasuresTheOffsetsAgainAndClearsThemInRange);
  RUN_TEST(test_drive_isr_AClearWithTheAmplifierStillBrokenKeepsItLatched);
  return UNITY_END();
}
