/* SPDX-License-Identifier: MIT */
/* CAN codec: byte layout, ranges, DLC and id checks. The DBC itself is checked against this codec
 * by tests/python/test_can_dbc.py. */
#include <string.h>

#include "pour/can_codec.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_can_id_PlacesNodeAboveCmd(void) {
  TEST_ASSERT_EQUAL_HEX16(0x012, pour_can_id(0, POUR_CAN_CMD_TORQUE));
  TEST_ASSERT_EQUAL_HEX16((5u << 5) | 0x10u, pour_can_id(5, POUR_CAN_CMD_STATE_A));
  TEST_ASSERT_EQUAL_HEX16(0x7FF, pour_can_id(63, 31));
}

static void test_can_pack_state_a_IsLittleEndianWithSignedTheta(void) {
  pour_can_state_a_t a = {.theta_urad = -2, .omega_urad_s = 0x01020304, .seq_low = 0xAB};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_a(1, &a, &f));
  const uint8_t want[8] = {0xFE, 0xFF, 0xFF, 0x04, 0x03, 0x02, 0x01, 0xAB};
  TEST_ASSERT_EQUAL_HEX16(0x030, f.id);
  TEST_ASSERT_EQUAL_UINT8(8, f.dlc);
  TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f.data, 8);
  pour_can_state_a_t back;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_state_a(&f, &back));
  TEST_ASSERT_EQUAL_INT32(-2, back.theta_urad);
  TEST_ASSERT_EQUAL_INT32(0x01020304, back.omega_urad_s);
  TEST_ASSERT_EQUAL_UINT8(0xAB, back.seq_low);
}

static void test_can_state_a_RoundTripsRangeEdges(void) {
  const int32_t thetas[] = {-POUR_CAN_THETA_MAX_URAD, -1, 0, 1, POUR_CAN_THETA_MAX_URAD};
  const int32_t omegas[] = {-POUR_CAN_OMEGA_MAX_URAD_S, -1, 0, 1, POUR_CAN_OMEGA_MAX_URAD_S};
  for (unsigned i = 0; i < 5; ++i) {
    pour_can_state_a_t a = {.theta_urad = thetas[i], .omega_urad_s = omegas[4 - i], .seq_low = (uint8_t)i};
    pour_can_frame_t f;
    pour_can_state_a_t b;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_a(0, &a, &f));
    TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_state_a(&f, &b));
    TEST_ASSERT_EQUAL_INT32(a.theta_urad, b.theta_urad);
    TEST_ASSERT_EQUAL_INT32(a.omega_urad_s, b.omega_urad_s);
  }
}

static void test_can_pack_RefusesOutOfRangeAndLeavesFrame(void) {
  pour_can_frame_t f;
  memset(&f, 0x5A, sizeof f);
  pour_can_state_a_t a = {.theta_urad = POUR_CAN_THETA_MAX_URAD + 1, .omega_urad_s = 0, .seq_low = 0};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_state_a(0, &a, &f));
  TEST_ASSERT_EQUAL_HEX8(0x5A, f.data[0]);
  a.theta_urad = 0;
  a.omega_urad_s = -POUR_CAN_OMEGA_MAX_URAD_S - 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_state_a(0, &a, &f));
  pour_can_state_b_t b = {.seq = 1, .v_rotating = -1, .v_target = 0, .v_spill = 0};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_state_b(0, &b, &f));
  pour_can_torque_t t = {.seq = 0, .torque = 0, .action = 16, .mode = 0, .limits = 0};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_torque(0, &t, &f));
  pour_can_heartbeat_t hb = {.mode = 4};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_heartbeat(0, &hb, &f));
  pour_can_estop_t e = {.assert_estop = 2};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_estop(0, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_command(64, POUR_CAN_CMD_CLEAR_ERRORS, &f));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_command(0, POUR_CAN_CMD_CLEAR_ERRORS, NULL));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_command(0, POUR_CAN_CMD_ESTOP, &f)); /* has a signal */
  pour_can_identity_t id = {.weights_hash = 1u, .tau_max_cnm = 2000u, .fw_version = 2u, .init_status = 1};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_identity(0, &id, &f)); /* no positive status exists */
  TEST_ASSERT_EQUAL_HEX8(0x5A, f.data[0]);
}

static void test_can_unpack_state_a_RejectsThetaPastRange(void) {
  pour_can_frame_t f = {.id = POUR_CAN_CMD_STATE_A, .dlc = 8, .data = {0}};
  /* 3,200,001 µrad = 0x30D401 */
  f.data[0] = 0x01;
  f.data[1] = 0xD4;
  f.data[2] = 0x30;
  pour_can_state_a_t a = {.theta_urad = 7, .omega_urad_s = 7, .seq_low = 7};
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_state_a(&f, &a));
  TEST_ASSERT_EQUAL_INT32(7, a.theta_urad);
  f.data[0] = 0x00; /* 3,200,000: the edge itself is in range */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_state_a(&f, &a));
  TEST_ASSERT_EQUAL_INT32(POUR_CAN_THETA_MAX_URAD, a.theta_urad);
}

static void test_can_state_b_RoundTripsAndRejectsNegativeVolume(void) {
  pour_can_state_b_t b = {.seq = 0xBEEF, .v_rotating = 32767, .v_target = 0, .v_spill = 1};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_b(2, &b, &f));
  const uint8_t want[8] = {0xEF, 0xBE, 0xFF, 0x7F, 0x00, 0x00, 0x01, 0x00};
  TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f.data, 8);
  pour_can_state_b_t back;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_state_b(&f, &back));
  TEST_ASSERT_EQUAL_UINT16(0xBEEF, back.seq);
  TEST_ASSERT_EQUAL_INT16(32767, back.v_rotating);
  TEST_ASSERT_EQUAL_INT16(1, back.v_spill);
  f.data[5] = 0x80; /* v_target = -32768 */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_state_b(&f, &back));
}

static void test_can_torque_RoundTripsFullQ15Range(void) {
  const q15_t values[] = {POUR_Q15_MIN, -1, 0, 1, POUR_Q15_MAX};
  for (unsigned i = 0; i < 5; ++i) {
    pour_can_torque_t t = {.seq = (uint16_t)(65535u - i), .torque = values[i], .action = 15, .mode = 3,
                           .limits = 15};
    pour_can_frame_t f;
    pour_can_torque_t back;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_torque(0, &t, &f));
    TEST_ASSERT_EQUAL_UINT8(7, f.dlc);
    TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&f, &back));
    TEST_ASSERT_EQUAL_INT16(values[i], back.torque);
    TEST_ASSERT_EQUAL_UINT16(t.seq, back.seq);
    TEST_ASSERT_EQUAL_UINT8(15, back.action);
  }
}

static void test_can_heartbeat_CarriesOnlyNamedFaultBits(void) {
  pour_can_heartbeat_t hb = {.mode = 2, .faults = 0xFFFF, .rx_dropped = 0x1234, .overruns = 0xFFFF,
                             .counter = 255};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_heartbeat(0, &hb, &f));
  const uint8_t want[8] = {0x02, 0xFF, 0x07, 0x34, 0x12, 0xFF, 0xFF, 0xFF};
  TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f.data, 8);
  pour_can_heartbeat_t back;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&f, &back));
  TEST_ASSERT_EQUAL_HEX16(POUR_CAN_HEARTBEAT_FAULT_MASK, back.faults);
  TEST_ASSERT_EQUAL_UINT16(0x1234, back.rx_dropped);
  TEST_ASSERT_EQUAL_UINT8(255, back.counter);
}

static void test_can_unpack_RejectsWrongDlcAndWrongCmd(void) {
  pour_can_frame_t f;
  pour_can_estop_t e = {.assert_estop = 1};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(0, &e, &f));
  f.dlc = 2;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_unpack_estop(&f, &e));
  f.dlc = 1;
  f.data[0] = 2;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_estop(&f, &e));
  pour_can_state_b_t b;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_unpack_state_b(&f, &b));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(3, POUR_CAN_CMD_CLEAR_ERRORS, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_command(&f, POUR_CAN_CMD_CLEAR_ERRORS));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_unpack_command(&f, POUR_CAN_CMD_RESET));
  f.dlc = 1;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_unpack_command(&f, POUR_CAN_CMD_CLEAR_ERRORS));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_unpack_command(NULL, POUR_CAN_CMD_CLEAR_ERRORS));
}

static void test_can_identity_RoundTripsHashScaleVersionAndNegativeStatus(void) {
  const pour_can_identity_t id = {.weights_hash = 0xfedcba98u, .tau_max_cnm = 2000u, .fw_version = 2u,
                                  .init_status = (int8_t)POUR_ECORRUPT};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_identity(5, &id, &f));
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(5, POUR_CAN_CMD_IDENTITY), f.id);
  pour_can_identity_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_identity(&f, &got));
  TEST_ASSERT_EQUAL_HEX32(0xfedcba98u, got.weights_hash);
  TEST_ASSERT_EQUAL_UINT16(2000u, got.tau_max_cnm);
  TEST_ASSERT_EQUAL_UINT8(2u, got.fw_version);
  TEST_ASSERT_EQUAL_INT8(POUR_ECORRUPT, got.init_status);
  f.data[7] = 1; /* a positive status is out of range */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_identity(&f, &got));
}

static void test_can_classify_SeparatesNodesCmdsAndDlcs(void) {
  const uint32_t accept = 1u << POUR_CAN_CMD_STATE_A;
  pour_can_frame_t f = {.id = pour_can_id(4, POUR_CAN_CMD_STATE_A), .dlc = 8, .data = {0}};
  uint8_t cmd = 0xFF;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_classify(&f, 4, accept, &cmd));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CMD_STATE_A, cmd);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OTHER_NODE, pour_can_classify(&f, 5, accept, &cmd));
  f.dlc = 7;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_classify(&f, 4, accept, &cmd));
  f.id = pour_can_id(4, POUR_CAN_CMD_TORQUE); /* defined, but not accepted here */
  f.dlc = 7;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_classify(&f, 4, accept, &cmd));
  f.id = pour_can_id(4, 0x1F); /* not defined at all */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_classify(&f, 4, 0xFFFFFFFFu, &cmd));
  f.id = 0x800; /* not an 11-bit id */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_classify(&f, 4, 0xFFFFFFFFu, &cmd));
  TEST_ASSERT_EQUAL_INT(-1, pour_can_dlc_of(0));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_can_id_PlacesNodeAboveCmd);
  RUN_TEST(test_can_pack_state_a_IsLittleEndianWithSignedTheta);
  RUN_TEST(test_can_state_a_RoundTripsRangeEdges);
  RUN_TEST(test_can_pack_RefusesOutOfRangeAndLeavesFrame);
  RUN_TEST(test_can_unpack_state_a_RejectsThetaPastRange);
  RUN_TEST(test_can_state_b_RoundTripsAndRejectsNegativeVolume);
  RUN_TEST(test_can_torque_RoundTripsFullQ15Range);
  RUN_TEST(test_can_heartbeat_CarriesOnlyNamedFaultBits);
  RUN_TEST(test_can_unpack_RejectsWrongDlcAndWrongCmd);
  RUN_TEST(test_can_identity_RoundTripsHashScaleVersionAndNegativeStatus);
  RUN_TEST(test_can_classify_SeparatesNodesCmdsAndDlcs);
  return UNITY_END();
}
