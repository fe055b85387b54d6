/* SPDX-License-Identifier: MIT */
#include "pour/board_facts.h"
#include <string.h>

#include "drive_script.h"
#include "pour/drive.h"
#include "unity.h"

static pour_drive_t drv;
static pour_drive_config_t cfg;
static pour_drive_output_t out;

/* ADC counts of a phase current [mA, into the motor] and of a bus voltage [mV] on the board (pour/board_facts.h:
 * the amplifier's output falls as current flows into the motor) */
static uint16_t adc_of_ma(int32_t ma) {
  return (uint16_t)(POUR_BOARD_OFFSET_NOMINAL_COUNTS +
                    POUR_BOARD_CURRENT_SIGN * (int64_t)ma * POUR_BOARD_SHUNT_UOHM * POUR_BOARD_AMP_GAIN_MILLI * 4096 /
                        ((int64_t)POUR_BOARD_ADC_VREF_MV * 1000000000LL));
}
static uint16_t adc_of_mv(int32_t mv) {
  return (uint16_t)((int64_t)mv * 4096 * 1000 / ((int64_t)POUR_BOARD_ADC_VREF_MV * POUR_BOARD_VBUS_DIVIDER_MILLI));
}

static pour_drive_sample_t sample(int32_t ia, int32_t ib, int32_t ic, int32_t vbus_mv, uint16_t enc) {
  pour_drive_sample_t s;
  s.adc_phase[0] = adc_of_ma(ia);
  s.adc_phase[1] = adc_of_ma(ib);
  s.adc_phase[2] = adc_of_ma(ic);
  s.adc_vbus = adc_of_mv(vbus_mv);
  s.encoder = enc;
  return s;
}

static void run_calibration(void) {
  const pour_drive_sample_t s = sample(0, 0, 0, 24000, 0);
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

void setUp(void) {
  cfg = pour_drive_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_drive_init(&drv, &cfg));
}
void tearDown(void) {}

static void assert_held(uint16_t fault) {
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv.state);
  TEST_ASSERT_TRUE((out.faults & fault) != 0u);
  TEST_ASSERT_EQUAL_UINT8(1, out.brake);
  for (int k = 0; k < 3; ++k) TEST_ASSERT_EQUAL_UINT16(0, out.compare[k]);
}

static void test_drive_DefaultConfigIsValid(void) { TEST_ASSERT_NULL(pour_drive_config_check(&cfg)); }

static void test_drive_ConfigCheckNamesTheBadField(void) {
  struct { const char *name; pour_drive_config_t c; } cases[13];
  for (int k = 0; k < 13; ++k) cases[k].c = cfg;
  cases[0].name = "bandwidth_rad_s"; cases[0].c.bandwidth_rad_s = 6284; /* above 2π·20 kHz/20 = 6283 */
  cases[1].name = "pwm_hz"; cases[1].c.pwm_hz = 10000;                 /* audible */
  cases[2].name = "r_phase_uohm"; cases[2].c.r_phase_uohm = 0;
  cases[3].name = "ld_nh"; cases[3].c.ld_nh = 20000000;
  cases[4].name = "pole_pairs"; cases[4].c.pole_pairs = 0;
  cases[5].name = "overcurrent_ma"; cases[5].c.overcurrent_ma = cfg.current_limit_ma;
  cases[6].name = "encoder_cpr"; cases[6].c.encoder_cpr = 4000;
  cases[7].name = "regen_on_mv"; cases[7].c.regen_on_mv = cfg.vbus_ov_mv;
  cases[8].name = "encoder_reversed"; cases[8].c.encoder_reversed = 2;
  cases[9].name = "cal_current_ma"; cases[9].c.cal_current_ma = cfg.current_limit_ma + 1u;
  cases[10].name = "cal_l_test_mv"; cases[10].c.cal_l_test_mv = 99;
  cases[11].name = "cal_motion_urad"; cases[11].c.cal_motion_urad = 9817; /* < 2π/(32·20): a turn would not fit */
  cases[12].name = "cal_motion_urad"; cases[12].c.cal_motion_urad = 3141593 + 1;
  for (int k = 0; k < 13; ++k) {
    TEST_ASSERT_EQUAL_STRING(cases[k].name, pour_drive_config_check(&cases[k].c));
    TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_drive_init(&drv, &cases[k].c));
  }
  cfg.bandwidth_rad_s = 6283;
  TEST_ASSERT_NULL(pour_drive_config_check(&cfg));
}

static void test_drive_CalibratesWithThePwmOff(void) {
  const pour_drive_sample_t s = sample(0, 0, 0, 24000, 0);
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_UINT8(0, out.pwm_enable);
  TEST_ASSERT_EQUAL_UINT8(1, out.brake);
  run_calibration();
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_UINT8(1, out.pwm_enable);
  TEST_ASSERT_EQUAL_UINT16(0, out.faults);
}

static void test_drive_BrokenAmplifierLatchesTheOffsetFault(void) {
  pour_drive_sample_t s = sample(0, 0, 0, 24000, 0);
  s.adc_phase[1] = 2048; /* mid-rail, the old belief about the bias: outside the board's band, refused */
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, out.faults);
  TEST_ASSERT_EQUAL_UINT8(0, out.pwm_enable); /* currents unknown: the bridge stays off, the brake holds */
  TEST_ASSERT_EQUAL_UINT8(1, out.brake);
  pour_drive_tick(&drv, 5000, 0);
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_UINT8(0, out.pwm_enable);
}

static void test_drive_TorqueBecomesTheQCurrent(void) {
  run_calibration();
  pour_drive_tick(&drv, 20000, 0); /* 20 N·m / (20 · 0.9 · 0.0404 N·m/A) = 27.50 A */
  TEST_ASSERT_INT_WITHIN(3, 27503 * 32768 / 64000, drv.iq_cmd_q15);
  pour_drive_tick(&drv, 20000, -5); /* braking: the gearbox's loss helps, η² less current */
  TEST_ASSERT_INT_WITHIN(3, 27503 * 81 / 100 * 32768 / 64000, drv.iq_cmd_q15);
  pour_drive_tick(&drv, -40000, 0); /* beyond the 36 A limit */
  TEST_ASSERT_EQUAL_INT32(-36000 * 32768 / 64000, drv.iq_cmd_q15);
  const pour_drive_sample_t s = sample(0, 0, 0, 24000, 0);
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_INT16(-18432, out.iq_ref);
}

static void test_drive_OvercurrentTripsToShortedPhasesAndTheBrake(void) {
  run_calibration();
  const pour_drive_sample_t s = sample(46000, -23000, -23000, 24000, 0);
  pour_drive_isr(&drv, &s, &out);
  assert_held(POUR_DRIVE_FAULT_OVERCURRENT);
  TEST_ASSERT_EQUAL_UINT8(1, out.pwm_enable); /* low sides on: the windings shorted */
}

static void test_drive_BusOutOfRangeTrips(void) {
  run_calibration();
  pour_drive_sample_t s = sample(0, 0, 0, 30500, 0);
  pour_drive_isr(&drv, &s, &out);
  assert_held(POUR_DRIVE_FAULT_OVERVOLTAGE);
  setUp();
  run_calibration();
  s = sample(0, 0, 0, 9000, 0);
  pour_drive_isr(&drv, &s, &out);
  assert_held(POUR_DRIVE_FAULT_UNDERVOLTAGE);
}

static void test_drive_FluxBrakingStartsAboveRegenOn(void) {
  run_calibration();
  pour_drive_sample_t s = sample(0, 0, 0, 24400, 0);
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_INT16(0, out.id_ref);
  s = sample(0, 0, 0, 25100, 0);
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_TRUE((out.limits & POUR_DRIVE_LIMIT_FLUX_BRAKE) != 0u);
  TEST_ASSERT_INT_WITHIN(400, 20000 * 32768 / 64000, out.id_ref); /* the ADC's 15 mV steps */
  cfg.regen_enabled = 0;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_drive_init(&drv, &cfg));
  run_calibration();
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_INT16(0, out.id_ref);
}

static void test_drive_CurrentsNotSummingToZeroTripThePhaseFault(void) {
  run_calibration();
  const pour_drive_sample_t s = sample(5000, 0, 0, 24000, 0); /* 5 A leaves through no other phase */
  pour_drive_isr(&drv, &s, &out);
  assert_held(POUR_DRIVE_FAULT_PHASE);
}

static void test_drive_OpenPhaseTripsWhenTheLoopCannotFollow(void) {
  /* the references ask for 10 A while the phases carry nothing: the loop saturates, then trips after
   * phase_loss_ms */
  run_calibration();
  pour_drive_tick(&drv, 7000, 0);
  const pour_drive_sample_t s = sample(0, 0, 0, 24000, 0);
  uint32_t n = 0;
  while (drv.state == POUR_DRIVE_RUN && n < 20000u) {
    pour_drive_isr(&drv, &s, &out);
    ++n;
  }
  assert_held(POUR_DRIVE_FAULT_PHASE);
  TEST_ASSERT_TRUE(n > 20u * 20u);    /* not before the loop had its 20 ms */
  TEST_ASSERT_TRUE(n < 20u * 20u + 400u); /* saturating takes a few ms at this bandwidth */
}

static void test_drive_EncoderCountingTheWrongWayTrips(void) {
  run_calibration();
  /* the output turns +25 mrad; the motor should have turned +325 counts, its encoder went −325 */
  uint16_t enc = 0;
  for (int k = 0; k < 25; ++k) {
    for (int p = 0; p < 20; ++p) {
      enc = (uint16_t)((enc - (p % 3 == 0 ? 1u : 0u)) & 4095u);
      const pour_drive_sample_t s = sample(0, 0, 0, 24000, enc);
      pour_drive_isr(&drv, &s, &out);
    }
    pour_drive_tick(&drv, 0, 1000);
  }
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv.state);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_ENCODER_DIRECTION, drv.faults);
}

static void test_drive_EncoderCountingTheRightWayPasses(void) {
  run_calibration();
  uint16_t enc = 0;
  for (int k = 0; k < 50; ++k) {
    for (int p = 0; p < 20; ++p) {
      enc = (uint16_t)((enc + (p % 3 == 0 ? 1u : 0u)) & 4095u);
      const pour_drive_sample_t s = sample(0, 0, 0, 24000, enc);
      pour_drive_isr(&drv, &s, &out);
    }
    pour_drive_tick(&drv, 0, 1000);
  }
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

static void test_drive_I2tBudgetTripsAtItsIntegral(void) {
  /* 30 A measured on q (angle 0: q along β): (900 − 3.29²) A² over 466 A²·s trips after 0.524 s */
  run_calibration();
  const int32_t ib = 30000 * 866 / 1000;
  const pour_drive_sample_t s = sample(0, ib, -ib, 24000, 0);
  int ms = 0;
  while (drv.state == POUR_DRIVE_RUN && ms < 6000) {
    for (int p = 0; p < 20; ++p) pour_drive_isr(&drv, &s, &out);
    pour_drive_tick(&drv, 20000, 0);
    ++ms;
  }
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_I2T, drv.faults);
  TEST_ASSERT_INT_WITHIN(10, 524, ms);
}

static uint32_t rng = 12345u;
static uint32_t next(void) { return pour_drive_script_rng(&rng); }

static void test_drive_AnyInputGivesDutiesInRange(void) {
  for (int trial = 0; trial < 200; ++trial) {
    setUp();
    run_calibration();
    for (int k = 0; k < 200 && drv.state == POUR_DRIVE_RUN; ++k) {
      pour_drive_sample_t s;
      for (int p = 0; p < 3; ++p) s.adc_phase[p] = (uint16_t)(next() & 4095u);
      s.adc_vbus = (uint16_t)(next() & 4095u);
      s.encoder = (uint16_t)(next() & 4095u);
      if (k % 20 == 0) pour_drive_tick(&drv, (int32_t)(next() % 80001u) - 40000, 0);
      pour_drive_isr(&drv, &s, &out);
      for (int p = 0; p < 3; ++p) {
        TEST_ASSERT_TRUE(out.compare[p] <= drv.period);
        TEST_ASSERT_TRUE(out.duty[p] >= 0 && out.duty[p] <= POUR_FOC_DUTY_ONE);
      }
    }
  }
}

static void test_drive_TripFromOutsideLatches(void) {
  run_calibration();
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_HW_OVERCURRENT);
  const pour_drive_sample_t s = sample(0, 0, 0, 24000, 0);
  pour_drive_isr(&drv, &s, &out);
  assert_held(POUR_DRIVE_FAULT_HW_OVERCURRENT);
}

static const pour_drive_sample_t *quiet(void) {
  static pour_drive_sample_t s;
  s = sample(0, 0, 0, 24000, 0);
  return &s;
}

/* Trips fault from RUN, a quiet period, then a clear: RUN at zero current, or the fault kept. */
static void assert_clear(uint16_t fault, int clears) {
  setUp();
  run_calibration();
  pour_drive_tick(&drv, 20000, 0);
  pour_drive_trip(&drv, fault);
  pour_drive_isr(&drv, quiet(), &out);
  assert_held(fault);
  TEST_ASSERT_EQUAL_HEX16(clears ? 0u : fault, pour_drive_clear_faults(&drv));
  TEST_ASSERT_EQUAL_INT(clears ? POUR_DRIVE_RUN : POUR_DRIVE_FAULTED, drv.state);
  TEST_ASSERT_EQUAL_HEX16(clears ? 0u : fault, drv.faults);
  pour_drive_isr(&drv, quiet(), &out);
  TEST_ASSERT_EQUAL_UINT8(clears ? 0u : 1u, out.brake);
  TEST_ASSERT_EQUAL_INT16(0, out.iq_ref); /* the torque before the fault is gone */
}

static void test_drive_ClearErrorsClearsWhatItCanJudgeAndKeepsTheRest(void) {
  assert_clear(POUR_DRIVE_FAULT_OVERCURRENT, 1);
  assert_clear(POUR_DRIVE_FAULT_HW_OVERCURRENT, 1);
  assert_clear(POUR_DRIVE_FAULT_OVERVOLTAGE, 1);
  assert_clear(POUR_DRIVE_FAULT_UNDERVOLTAGE, 1);
  assert_clear(POUR_DRIVE_FAULT_OVERTEMP, 1);
  assert_clear(POUR_DRIVE_FAULT_PHASE, 1);
  assert_clear(POUR_DRIVE_FAULT_I2T, 1); /* cold: no heat accrued */
  assert_clear(POUR_DRIVE_FAULT_ENCODER_DIRECTION, 0);
  assert_clear(POUR_DRIVE_FAULT_ENCODER_MISMATCH, 0);
  assert_clear(POUR_DRIVE_FAULT_CALIBRATION, 0);
  for (uint16_t bit = 1u; bit <= POUR_DRIVE_FAULT_ALL; bit = (uint16_t)(bit << 1))
    if (bit != POUR_DRIVE_FAULT_CURRENT_OFFSET) assert_clear(bit, (bit & POUR_DRIVE_FAULT_CLEARABLE) != 0u);
}

/* CURRENT_OFFSET: a clear measures the offsets again with the bridge off, the fault latched meanwhile; in
 * range it clears (RUN at zero current), out of range it stays. */
static void test_drive_ClearOfACurrentOffsetMeasuresTheOffsetsAgain(void) {
  for (int bad = 0; bad <= 1; ++bad) {
    setUp();
    run_calibration();
    pour_drive_trip(&drv, POUR_DRIVE_FAULT_CURRENT_OFFSET);
    pour_drive_isr(&drv, quiet(), &out);
    TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, pour_drive_clear_faults(&drv));
    TEST_ASSERT_EQUAL_INT(POUR_DRIVE_CALIBRATING, drv.state);
    pour_drive_sample_t s = *quiet();
    if (bad) s.adc_phase[1] = (uint16_t)(s.adc_phase[1] + 400u); /* the amplifier still 400 counts off */
    for (int k = 0; k < POUR_CURRENT_SENSE_CAL_SAMPLES; ++k) {
      TEST_ASSERT_EQUAL_INT(POUR_DRIVE_CALIBRATING, drv.state);
      TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET, drv.faults);
      pour_drive_isr(&drv, &s, &out);
      TEST_ASSERT_EQUAL_UINT8(0u, out.pwm_enable); /* all six switches off while it measures */
      TEST_ASSERT_EQUAL_UINT8(1u, out.brake);
    }
    TEST_ASSERT_EQUAL_INT(bad ? POUR_DRIVE_FAULTED : POUR_DRIVE_RUN, drv.state);
    TEST_ASSERT_EQUAL_HEX16(bad ? POUR_DRIVE_FAULT_CURRENT_OFFSET : 0u, drv.faults);
    pour_drive_isr(&drv, quiet(), &out);
    TEST_ASSERT_EQUAL_UINT8(bad ? 1u : 0u, out.brake);
    TEST_ASSERT_EQUAL_INT16(0, out.iq_ref);
  }
}

static void test_drive_ClearKeepsTheKeptBitAndClearsTheOthers(void) {
  run_calibration();
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_OVERCURRENT | POUR_DRIVE_FAULT_ENCODER_DIRECTION);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_ENCODER_DIRECTION, pour_drive_clear_faults(&drv));
  pour_drive_isr(&drv, quiet(), &out);
  assert_held(POUR_DRIVE_FAULT_ENCODER_DIRECTION);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_ENCODER_DIRECTION, out.faults);
}

static void test_drive_ClearKeepsTheBusFaultWhileTheBusIsOut(void) {
  run_calibration();
  pour_drive_sample_t s = sample(0, 0, 0, 30500, 0);
  pour_drive_isr(&drv, &s, &out);
  pour_drive_isr(&drv, &s, &out);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_OVERVOLTAGE, pour_drive_clear_faults(&drv));
  s = sample(0, 0, 0, 9000, 0);
  pour_drive_isr(&drv, &s, &out);
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_UNDERVOLTAGE);
  /* the bus no longer over: that one clears, the one still out stays */
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_UNDERVOLTAGE, pour_drive_clear_faults(&drv));
  pour_drive_isr(&drv, quiet(), &out); /* back in range */
  TEST_ASSERT_EQUAL_HEX16(0u, pour_drive_clear_faults(&drv));
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

/* A clear right after the offsets were measured again judges the bus as it is now: the bus rose above its
 * trip while the drive measured (the gates off), so OVERVOLTAGE stays, and the loop does not restart. */
static void test_drive_ClearAfterTheOffsetsJudgesTheBusOfNow(void) {
  run_calibration();
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_CURRENT_OFFSET | POUR_DRIVE_FAULT_OVERVOLTAGE);
  pour_drive_isr(&drv, quiet(), &out); /* a faulted period at 24 V */
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CURRENT_OFFSET | POUR_DRIVE_FAULT_OVERVOLTAGE, pour_drive_clear_faults(&drv));
  const pour_drive_sample_t high = sample(0, 0, 0, 30500, 0);
  for (int k = 0; k < POUR_CURRENT_SENSE_CAL_SAMPLES; ++k) pour_drive_isr(&drv, &high, &out);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv.state); /* the offsets passed; the bus fault is left */
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_OVERVOLTAGE, pour_drive_clear_faults(&drv));
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv.state);
}

static void test_drive_ClearKeepsTheI2tFaultUntilTheMotorCools(void) {
  run_calibration();
  const int32_t ib = 30000 * 866 / 1000;
  const pour_drive_sample_t hot = sample(0, ib, -ib, 24000, 0);
  while (drv.state == POUR_DRIVE_RUN) {
    for (int p = 0; p < 20; ++p) pour_drive_isr(&drv, &hot, &out);
    pour_drive_tick(&drv, 20000, 0);
  }
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_I2T, pour_drive_clear_faults(&drv));
  /* held at zero current it cools at i_cont²: half the 466 A²·s budget in 21.5 s */
  int ms = 0;
  while (pour_drive_clear_faults(&drv) != 0u && ms < 60000) {
    for (int p = 0; p < 20; ++p) pour_drive_isr(&drv, quiet(), &out);
    pour_drive_tick(&drv, 0, 0);
    ++ms;
  }
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
  TEST_ASSERT_INT_WITHIN(100, 21500, ms);
}

static void test_drive_ClearDoesNothingOutsideFaulted(void) {
  TEST_ASSERT_EQUAL_HEX16(0u, pour_drive_clear_faults(&drv));
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_CALIBRATING, drv.state); /* the offsets are still being measured */
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_OVERTEMP);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_OVERTEMP, pour_drive_clear_faults(&drv)); /* never measured */
  setUp();
  run_calibration();
  TEST_ASSERT_EQUAL_HEX16(0u, pour_drive_clear_faults(&drv));
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_drive_DefaultConfigIsValid);
  RUN_TEST(test_drive_ConfigCheckNamesTheBadField);
  RUN_TEST(test_drive_CalibratesWithThePwmOff);
  RUN_TEST(test_drive_BrokenAmplifierLatchesTheOffsetFault);
  RUN_TEST(test_drive_TorqueBecomesTheQCurrent);
  RUN_TEST(test_drive_OvercurrentTripsToShortedPhasesAndTheBrake);
  RUN_TEST(test_drive_BusOutOfRangeTrips);
  RUN_TEST(test_drive_FluxBrakingStartsAboveRegenOn);
  RUN_TEST(test_drive_CurrentsNotSummingToZeroTripThePhaseFault);
  RUN_TEST(test_drive_OpenPhaseTripsWhenTheLoopCannotFollow);
  RUN_TEST(test_drive_EncoderCountingTheWrongWayTrips);
  RUN_TEST(test_drive_EncoderCountingTheRightWayPasses);
  RUN_TEST(test_drive_I2tBudgetTripsAtItsIntegral);
  RUN_TEST(test_drive_AnyInputGivesDutiesInRange);
  RUN_TEST(test_drive_TripFromOutsideLatches);
  RUN_TEST(test_drive_ClearErrorsClearsWhatItCanJudgeAndKeepsTheRest);
  RUN_TEST(test_drive_ClearKeepsTheKeptBitAndClearsTheOthers);
  RUN_TEST(test_drive_ClearOfACurrentOffsetMeasuresTheOffsetsAgain);
  RUN_TEST(test_drive_ClearKeepsTheBusFaultWhileTheBusIsOut);
  RUN_TEST(test_drive_ClearAfterTheOffsetsJudgesTheBusOfNow);
  RUN_TEST(test_drive_ClearKeepsTheI2tFaultUntilTheMotorCools);
  RUN_TEST(test_drive_ClearDoesNothingOutsideFaulted);
  return UNITY_END();
}
