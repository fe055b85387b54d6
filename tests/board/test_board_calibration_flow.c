/* SPDX-License-Identifier: MIT */
/* The board's calibration flow (calibration_flow.c) with the real CAN node, drive and flash block, the
 * drive fed scripted samples (no motor: the closed loop with one is tests/sim/test_calibration.cpp): an open
 * circuit named on the bus with nothing stored, the e-stop ending it, a start the drive refuses, what a
 * controller that cannot measure answers, the brake-release interlock's refusals (tilted, not empty, no or
 * stale sensors) and its limits, a second start while one runs, a start from a latched encoder fault, and
 * the read-only CalibrationRead of what flash holds (a valid block, an erased page, a corrupt block).
 * Runs on the host and on the emulated Cortex-M4. */
#include <string.h>

#include "calibration_flow.h"
#include "flash_page_file.h"
#include "unity.h"

static pour_can_node_t node;
static pour_drive_t drv;
static pour_calibration_flow_t flow;
static pour_can_calibration_result_t sent[4];
static int n_sent;
static int released_outside;

/* The rig's sensor node: the output encoder (17 bits, 0 = upright) and the rotating scale; sending false: it
 * has gone quiet. */
static struct {
  bool sending;
  uint32_t encoder;
  int32_t scale_rotating_g;
} rig;

#define ENCODER_BITS 17u
#define DEG10_COUNTS(d10) ((uint32_t)(d10) * 131072u / 3600u) /* an angle in 0.1° as a count, rounded down */

void setUp(void) {
  flash_page_file_reset();
  pour_can_node_config_t nc = pour_can_node_default_config();
  nc.can_calibrate = true;
  nc.identity.init_status = (int8_t)POUR_ECALIBRATION;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &nc));
  const pour_drive_config_t dc = pour_drive_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_drive_init(&drv, &dc));
  pour_calibration_flow_init(&flow, POUR_CAL_EMPTY, NULL);
  n_sent = 0;
  released_outside = 0;
  rig.sending = true; /* upright, empty */
  rig.encoder = 0u;
  rig.scale_rotating_g = 0;
}

void tearDown(void) {}

/* One millisecond: the node's tick around the flow, and the drive's 20 periods on zero currents at 24 V. */
static void tick(pour_mode_t mode) {
  pour_control_input_t in;
  pour_can_node_begin_tick(&node, &in);
  const pour_sensors_t sample = {0u, rig.encoder, rig.scale_rotating_g, 0};
  const bool measuring = pour_calibration_flow_tick(&flow, &node, &drv, (uint8_t)mode, &f);
  pour_calibration_flow_sense(&flow, &node, &drv, &sample, rig.sending, ENCODER_BITS);
  pour_control_output_t out;
  memset(&out, 0, sizeof out);
  out.mode = (uint8_t)mode;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  const uint8_t n = pour_can_node_end_tick(&node, &out, 0u, tx);
  for (uint8_t k = 0; k < n; ++k) {
    if (n_sent < 4 && pour_can_unpack_calibration_result(&tx[k], &sent[n_sent]) == POUR_CAN_RX_OK) ++n_sent;
  }
  const pour_drive_sample_t s = {{2553, 2553, 2553}, 2867, 0}; /* the board's bias; 24 V */
  pour_drive_output_t o;
  for (int p = 0; p < 20; ++p) {
    pour_drive_isr(&drv, &s, &o);
    if (!o.brake && !measuring && drv.state != POUR_DRIVE_RUN) released_outside = 1;
  }
}

static void start(void) {
  pour_can_frame_t fr;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(0, POUR_CAN_CMD_CALIBRATION_START, &fr));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &fr));
}

static void test_calibration_flow_AnOpenCircuitIsNamedAndNothingStored(void) {
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE); /* the current offsets */
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
  start();
  for (int ms = 0; ms < 600; ++ms) tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(2, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, sent[0].status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_BAD_RESISTANCE, sent[1].status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_EMPTY, sent[1].stored);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv.state);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_CALIBRATION, drv.faults);
  TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, page[0]);
  TEST_ASSERT_EQUAL_INT8(POUR_ECALIBRATION, node.config.identity.init_status);
  TEST_ASSERT_FALSE(released_outside);
}

static void test_calibration_flow_TheEstopEndsIt(void) {
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE);
  start();
  for (int ms = 0; ms < 100; ++ms) tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_MEASURING, drv.state);
  tick(POUR_MODE_ESTOP);
  tick(POUR_MODE_ESTOP);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_FAULTED, drv.state);
  TEST_ASSERT_EQUAL_INT(2, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_ABORTED, sent[1].status);
}

/* A CalibrationStart the drive cannot start: the n-th answer ABORTED, at once, the drive left in state. */
static void assert_aborted_at_once(int n, pour_drive_state_t state) {
  start();
  tick(POUR_MODE_IDLE);
  tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(n, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_ABORTED, sent[n - 1].status);
  TEST_ASSERT_EQUAL_INT(state, drv.state);
}

static void test_calibration_flow_AStartTheDriveRefusesIsAborted(void) {
  /* before the current offsets are measured, and with a power-stage fault latched: refused at once */
  tick(POUR_MODE_IDLE);
  assert_aborted_at_once(1, POUR_DRIVE_CALIBRATING);
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE);
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_OVERTEMP);
  assert_aborted_at_once(2, POUR_DRIVE_FAULTED);
}

/* One CalibrationStart answered after the offsets, with the rig as set: the answer's status, and the drive
 * not started by a refusal. */
static uint8_t answer_with_rig(void) {
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE);
  start();
  tick(POUR_MODE_IDLE);
  tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(1, n_sent);
  return sent[0].status;
}

static void test_calibration_flow_TiltedIsRefusedNotUpright(void) {
  rig.encoder = DEG10_COUNTS(55); /* beyond the 5° of upright */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NOT_UPRIGHT, answer_with_rig());
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
  TEST_ASSERT_FALSE(released_outside);
}

static void test_calibration_flow_TiltedBackIsRefusedNotUpright(void) {
  rig.encoder = (1u << ENCODER_BITS) - DEG10_COUNTS(55); /* below upright: the count wraps */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NOT_UPRIGHT, answer_with_rig());
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

static void test_calibration_flow_LiquidInTheBucketIsRefusedNotEmpty(void) {
  rig.scale_rotating_g = 201;
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NOT_EMPTY, answer_with_rig());
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

static void test_calibration_flow_AScaleFarBelowItsTareIsNotEmpty(void) {
  rig.scale_rotating_g = -201;
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NOT_EMPTY, answer_with_rig());
}

static void test_calibration_flow_NoSampleSinceBootIsRefused(void) {
  rig.sending = false; /* no data is not "empty" */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NO_SENSORS, answer_with_rig());
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

static void test_calibration_flow_AStaleSampleIsRefused(void) {
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE); /* upright and empty ... */
  rig.sending = false;                                  /* ... then the sensor node goes quiet */
  for (int ms = 0; ms < (int)POUR_CALIBRATION_SAMPLE_MS - 1; ++ms) tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NO_SENSORS, answer_with_rig()); /* 21 ms and more */
  /* a sample out of the encoder's range is no sample either */
  rig.sending = true;
  rig.encoder = 1u << ENCODER_BITS;
  for (int ms = 0; ms < (int)POUR_CALIBRATION_SAMPLE_MS; ++ms) tick(POUR_MODE_IDLE);
  n_sent = 0;
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NO_SENSORS, answer_with_rig());
}

/* The latest sample of the tick decides, not the latest usable one: a count out of range (the core latches
 * BAD_INPUT on it) refuses the start although an upright, empty sample came 1 ms before, and so it does in
 * every tick of samples that alternate between good and out of range. */
static void test_calibration_flow_ALatestCountOutOfRangeRefusesAfterGoodSamples(void) {
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE); /* the offsets measured: the drive could start */
  for (int pair = 0; pair < 10; ++pair) {
    rig.encoder = 0u; /* upright and empty */
    tick(POUR_MODE_IDLE);
    rig.encoder = 1u << ENCODER_BITS;
    start();
    n_sent = 0;
    tick(POUR_MODE_IDLE); /* answered in this tick, on this tick's sample */
    TEST_ASSERT_EQUAL_INT(1, n_sent);
    TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NO_SENSORS, sent[0].status);
    TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
  }
  TEST_ASSERT_FALSE(released_outside);
}

static void test_calibration_flow_UprightAndEmptyWithinTheLimitsStarts(void) {
  rig.encoder = (1u << ENCODER_BITS) - DEG10_COUNTS(49);
  rig.scale_rotating_g = -200;
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, answer_with_rig());
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_MEASURING, drv.state);
}

/* A second CalibrationStart while the sequence runs: answered MEASURING again, nothing restarts, and the
 * one running ends with its own outcome (here the open circuit's). */
static void test_calibration_flow_ASecondStartWhileMeasuringIsAnsweredMeasuring(void) {
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, answer_with_rig());
  for (int ms = 0; ms < 50; ++ms) tick(POUR_MODE_IDLE);
  const uint32_t n_before = drv.cal.n;
  rig.encoder = DEG10_COUNTS(80); /* the sequence may move it: the interlock judges a start, not a run */
  start();
  tick(POUR_MODE_IDLE);
  tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(2, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, sent[1].status);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_MEASURING, drv.state);
  TEST_ASSERT_TRUE(drv.cal.n > n_before); /* the same stage's count runs on: not restarted */
  for (int ms = 0; ms < 600; ++ms) tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(3, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_BAD_RESISTANCE, sent[2].status);
}

/* An encoder fault latched (a slipped coupling, a reversed encoder) is cleared by a self-calibration only:
 * the start is accepted from it. */
static void test_calibration_flow_AnEncoderFaultMayBeCalibratedAway(void) {
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE);
  pour_drive_trip(&drv, POUR_DRIVE_FAULT_ENCODER_MISMATCH | POUR_DRIVE_FAULT_ENCODER_DIRECTION);
  TEST_ASSERT_EQUAL_HEX16(POUR_DRIVE_FAULT_ENCODER_MISMATCH | POUR_DRIVE_FAULT_ENCODER_DIRECTION,
                          pour_drive_clear_faults(&drv)); /* a ClearErrors keeps both */
  n_sent = 0;
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, answer_with_rig());
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_MEASURING, drv.state);
}

static void test_calibration_flow_AControllerThatCannotMeasureSaysSo(void) {
  pour_can_node_config_t nc = pour_can_node_default_config(); /* can_calibrate false: the Linux port's */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &nc));
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE);
  start();
  tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(1, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_UNAVAILABLE, sent[0].status);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state);
}

/* What main.c and board_loop do at boot, on this page: the block loaded and checked, handed to the node and
 * the flow. Returns the block's state. */
static pour_cal_status_t boot_from_flash(void) {
  pour_calibration_t cal;
  const pour_cal_status_t st = pour_calibration_load(&f, &cal);
  pour_can_calibration_result_t r;
  pour_calibration_can_result(st, &cal, POUR_CAN_CAL_UNAVAILABLE, &r);
  pour_can_node_set_calibration(&node, &r);
  pour_calibration_flow_init(&flow, st, &cal);
  return st;
}

/* A CalibrationRead and the tick that answers it: its one CalibrationResult. */
static pour_can_calibration_result_t read_back(pour_mode_t mode) {
  pour_can_frame_t fr;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(0, POUR_CAN_CMD_CALIBRATION_READ, &fr));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &fr));
  const int before = n_sent;
  tick(mode);
  TEST_ASSERT_EQUAL_INT(before + 1, n_sent);
  return sent[before];
}

static const pour_calibration_t good = {304000u, 231000u, -1, 8u, 200u << 8};

static void test_calibration_flow_AReadSendsTheStoredBlockInAnyMode(void) {
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, boot_from_flash());
  for (int ms = 0; ms < 20; ++ms) tick(POUR_MODE_IDLE); /* the current offsets: the drive ready */
  const pour_mode_t modes[] = {POUR_MODE_IDLE, POUR_MODE_RUN, POUR_MODE_FAULT, POUR_MODE_ESTOP};
  for (unsigned i = 0; i < sizeof modes / sizeof modes[0]; ++i) {
    const pour_can_calibration_result_t r = read_back(modes[i]);
    TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_STORED, r.status);
    TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, r.stored);
    TEST_ASSERT_EQUAL_UINT8(1u, r.encoder_reversed);
    TEST_ASSERT_EQUAL_UINT8(8u, r.pole_pairs);
    TEST_ASSERT_EQUAL_UINT16(304u, r.resistance_mohm);
    TEST_ASSERT_EQUAL_UINT16(231u, r.inductance_uh);
    TEST_ASSERT_EQUAL_UINT8(200u, r.electrical_offset);
    TEST_ASSERT_EQUAL_INT(POUR_DRIVE_RUN, drv.state); /* nothing started, the brake never released */
    TEST_ASSERT_FALSE(pour_can_node_take_calibration_start(&node));
  }
  TEST_ASSERT_EQUAL_INT(0, released_outside);
}

/* A read, in the given mode, of a page without a valid block: STORED, the block's state, and no values. */
static void assert_read_shows_no_block(pour_mode_t mode, uint8_t stored) {
  const pour_can_calibration_result_t r = read_back(mode);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_STORED, r.status);
  TEST_ASSERT_EQUAL_UINT8(stored, r.stored);
  TEST_ASSERT_EQUAL_UINT8(0u, r.pole_pairs);
  TEST_ASSERT_EQUAL_UINT16(0u, r.resistance_mohm);
}

static void test_calibration_flow_AReadOfAnErasedPageSaysEmpty(void) {
  TEST_ASSERT_EQUAL_INT(POUR_CAL_EMPTY, boot_from_flash());
  assert_read_shows_no_block(POUR_MODE_IDLE, POUR_CAN_CAL_EMPTY);
}

static void test_calibration_flow_AReadOfACorruptBlockSaysCorruptAndShowsNoValues(void) {
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  page[3] ^= 0x10u; /* one bit flipped in the stored words: the CRC no longer matches */
  TEST_ASSERT_EQUAL_INT(POUR_CAL_CORRUPT, boot_from_flash());
  assert_read_shows_no_block(POUR_MODE_FAULT, POUR_CAN_CAL_CORRUPT);
}

/* A read while the sequence runs: the block stored before it, and the measurement runs on. */
static void test_calibration_flow_AReadWhileMeasuringLeavesItRunning(void) {
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, pour_calibration_save(&f, &good));
  TEST_ASSERT_EQUAL_INT(POUR_CAL_OK, boot_from_flash());
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, answer_with_rig());
  const uint32_t n_before = drv.cal.n;
  const pour_can_calibration_result_t r = read_back(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_STORED, r.status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, r.stored);
  TEST_ASSERT_EQUAL_UINT16(304u, r.resistance_mohm);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_MEASURING, drv.state);
  TEST_ASSERT_TRUE(drv.cal.n > n_before);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_calibration_flow_AnOpenCircuitIsNamedAndNothingStored);
  RUN_TEST(test_calibration_flow_TheEstopEndsIt);
  RUN_TEST(test_calibration_flow_AStartTheDriveRefusesIsAborted);
  RUN_TEST(test_calibration_flow_AControllerThatCannotMeasureSaysSo);
  RUN_TEST(test_calibration_flow_TiltedIsRefusedNotUpright);
  RUN_TEST(test_calibration_flow_TiltedBackIsRefusedNotUpright);
  RUN_TEST(test_calibration_flow_LiquidInTheBucketIsRefusedNotEmpty);
  RUN_TEST(test_calibration_flow_AScaleFarBelowItsTareIsNotEmpty);
  RUN_TEST(test_calibration_flow_NoSampleSinceBootIsRefused);
  RUN_TEST(test_calibration_flow_AStaleSampleIsRefused);
  RUN_TEST(test_calibration_flow_ALatestCountOutOfRangeRefusesAfterGoodSamples);
  RUN_TEST(test_calibration_flow_UprightAndEmptyWithinTheLimitsStarts);
  RUN_TEST(test_calibration_flow_ASecondStartWhileMeasuringIsAnsweredMeasuring);
  RUN_TEST(test_calibration_flow_AnEncoderFaultMayBeCalibratedAway);
  RUN_TEST(test_calibration_flow_AReadSendsTheStoredBlockInAnyMode);
  RUN_TEST(test_calibration_flow_AReadOfAnErasedPageSaysEmpty);
  RUN_TEST(test_calibration_flow_AReadOfACorruptBlockSaysCorruptAndShowsNoValues);
  RUN_TEST(test_calibration_flow_AReadWhileMeasuringLeavesItRunning);
  return UNITY_END();
}
