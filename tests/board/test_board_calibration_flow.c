/* SPDX-License-Identifier: MIT */
/* The board's calibration flow (calibration_flow.c) with the real CAN node, drive and flash block, the
 * drive fed scripted samples (no motor: the closed loop with one is tests/sim/test_calibration.cpp): an open
 * circuit named on the bus with nothing stored, the e-stop ending it, a start the drive refuses, and what a
 * controller that cannot measure answers. Runs on the host and on the emulated Cortex-M4. */
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
}

void tearDown(void) {}

/* One millisecond: the node's tick around the flow, and the drive's 20 periods on zero currents at 24 V. */
static void tick(pour_mode_t mode) {
  pour_control_input_t in;
  pour_can_node_begin_tick(&node, &in);
  const bool measuring = pour_calibration_flow_tick(&flow, &node, &drv, (uint8_t)mode, &f);
  pour_control_output_t out;
  memset(&out, 0, sizeof out);
  out.mode = (uint8_t)mode;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  const uint8_t n = pour_can_node_end_tick(&node, &out, 0u, tx);
  for (uint8_t k = 0; k < n; ++k) {
    if (n_sent < 4 && pour_can_unpack_calibration_result(&tx[k], &sent[n_sent]) == POUR_CAN_RX_OK) ++n_sent;
  }
  const pour_drive_sample_t s = {{2048, 2048, 2048}, 1554, 0};
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

static void test_calibration_flow_AStartTheDriveRefusesIsAborted(void) {
  /* before the current offsets are measured (and likewise with a power-stage fault latched) */
  start();
  tick(POUR_MODE_IDLE);
  tick(POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_INT(2, n_sent);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, sent[0].status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_ABORTED, sent[1].status);
  TEST_ASSERT_EQUAL_INT(POUR_DRIVE_CALIBRATING, drv.state);
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

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_calibration_flow_AnOpenCircuitIsNamedAndNothingStored);
  RUN_TEST(test_calibration_flow_TheEstopEndsIt);
  RUN_TEST(test_calibration_flow_AStartTheDriveRefusesIsAborted);
  RUN_TEST(test_calibration_flow_AControllerThatCannotMeasureSaysSo);
  return UNITY_END();
}
