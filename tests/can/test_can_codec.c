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
  TEST_ASSERT_EQUAL_HEX16((5u << 5) | 0x10u, pour_can_id(5, POUR_CAN_CMD_SENSORS));
  TEST_ASSERT_EQUAL_HEX16(0x7FF, pour_can_id(63, 31));
}

static void test_can_pack_sensors_IsLittleEndianWithSignedScales(void) {
  pour_can_sensors_t m = {.seq_low = 0xAB, .encoder = 0x01FFFFu, .scale_rotating_g = -2, .scale_target_g = 12345};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(1, &m, &f));
  const uint8_t want[8] = {0xAB, 0xFF, 0xFF, 0x01, 0xFE, 0xFF, 0x39, 0x30};
  TEST_ASSERT_EQUAL_HEX16(0x030, f.id);
  TEST_ASSERT_EQUAL_UINT8(8, f.dlc);
  TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f.data, 8);
  pour_can_sensors_t back;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_sensors(&f, &back));
  TEST_ASSERT_EQUAL_UINT8(0xAB, back.seq_low);
  TEST_ASSERT_EQUAL_HEX32(0x01FFFFu, back.encoder);
  TEST_ASSERT_EQUAL_INT16(-2, back.scale_rotating_g);
  TEST_ASSERT_EQUAL_INT16(12345, back.scale_target_g);
}

static void test_can_sensors_RoundTripRangeEdges(void) {
  const uint32_t encoders[] = {0u, 1u, 0x1FFFFu, 0x20000u, POUR_CAN_ENCODER_MAX};
  const int16_t scales[] = {-POUR_CAN_SCALE_MAX_G, -1, 0, 1, POUR_CAN_SCALE_MAX_G};
  for (unsigned i = 0; i < 5; ++i) {
    pour_can_sensors_t m = {.seq_low = (uint8_t)(250u + i), .encoder = encoders[i], .scale_rotating_g = scales[i],
                            .scale_target_g = scales[4 - i]};
    pour_can_frame_t f;
    pour_can_sensors_t b;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(0, &m, &f));
    TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_sensors(&f, &b));
    TEST_ASSERT_EQUAL_UINT8(m.seq_low, b.seq_low);
    TEST_ASSERT_EQUAL_UINT32(m.encoder, b.encoder);
    TEST_ASSERT_EQUAL_INT16(m.scale_rotating_g, b.scale_rotating_g);
    TEST_ASSERT_EQUAL_INT16(m.scale_target_g, b.scale_target_g);
  }
}

static void test_can_pack_RefusesOutOfRangeAndLeavesFrame(void) {
  pour_can_frame_t f;
  memset(&f, 0x5A, sizeof f);
  pour_can_sensors_t m = {.seq_low = 0, .encoder = POUR_CAN_ENCODER_MAX + 1u, .scale_rotating_g = 0,
                          .scale_target_g = 0};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_sensors(0, &m, &f)); /* does not fit 24 bits */
  TEST_ASSERT_EQUAL_HEX8(0x5A, f.data[0]);
  m.encoder = 0u;
  m.scale_rotating_g = INT16_MIN; /* the overload code */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_sensors(0, &m, &f));
  m.scale_rotating_g = 0;
  m.scale_target_g = INT16_MIN;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_sensors(0, &m, &f));
  pour_can_torque_t t = {.seq = 0, .torque = 0, .action = 16, .mode = 0, .limits = 0};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_torque(0, &t, &f));
  pour_can_heartbeat_t hb = {.mode = 4};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_heartbeat(0, &hb, &f));
  hb.mode = 0;
  hb.refused = 16; /* a count mod 16: the port reduces it, the codec does not */
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

static void test_can_unpack_sensors_RejectsTheScaleOverloadCode(void) {
  pour_can_frame_t f = {.id = POUR_CAN_CMD_SENSORS, .dlc = 8, .data = {7, 1, 0, 0, 0x00, 0x80, 0, 0}};
  pour_can_sensors_t m = {.seq_low = 9, .encoder = 9, .scale_rotating_g = 9, .scale_target_g = 9};
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_sensors(&f, &m)); /* rotating -32768 */
  TEST_ASSERT_EQUAL_UINT8(9, m.seq_low);                                           /* untouched */
  f.data[5] = 0x00;
  f.data[7] = 0x80; /* target -32768 */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_sensors(&f, &m));
  f.data[6] = 0x01; /* -32767: the edge itself is in range */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_sensors(&f, &m));
  TEST_ASSERT_EQUAL_INT16(-POUR_CAN_SCALE_MAX_G, m.scale_target_g);
  TEST_ASSERT_EQUAL_UINT32(1u, m.encoder);
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
                             .counter = 255, .refused = 0xA};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_heartbeat(0, &hb, &f));
  const uint8_t want[8] = {0xA2, 0xFF, 0x0F, 0x34, 0x12, 0xFF, 0xFF, 0xFF}; /* Refused in Mode's high nibble; 12 fault bits */
  TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f.data, 8);
  pour_can_heartbeat_t back;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&f, &back));
  TEST_ASSERT_EQUAL_HEX16(POUR_CAN_HEARTBEAT_FAULT_MASK, back.faults);
  TEST_ASSERT_EQUAL_UINT16(0x1234, back.rx_dropped);
  TEST_ASSERT_EQUAL_UINT8(255, back.counter);
  TEST_ASSERT_EQUAL_UINT8(2, back.mode);
  TEST_ASSERT_EQUAL_UINT8(0xA, back.refused);
  f.data[0] = 0xA4; /* mode 4 does not exist, whatever the count beside it */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_heartbeat(&f, &back));
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
  pour_can_sensors_t m;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_unpack_sensors(&f, &m));
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

static void test_can_calibration_result_RoundTripsAndNamesTheReason(void) {
  const pour_can_calibration_result_t r = {.status = POUR_CAN_CAL_REFUSED_RUNNING, .stored = POUR_CAN_CAL_OK,
                                           .encoder_reversed = 1u, .pole_pairs = 8u, .resistance_mohm = 304u,
                                           .inductance_uh = 231u, .electrical_offset = 200u};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_calibration_result(2, &r, &f));
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(2, POUR_CAN_CMD_CALIBRATION_RESULT), f.id);
  TEST_ASSERT_EQUAL_HEX8(0x06u, f.data[0]); /* status 6 in bits 0..4, stored 0 in bits 5..7 */
  pour_can_calibration_result_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&f, &got));
  TEST_ASSERT_EQUAL_UINT8(r.status, got.status);
  TEST_ASSERT_EQUAL_UINT8(r.stored, got.stored);
  TEST_ASSERT_EQUAL_UINT8(1u, got.encoder_reversed);
  TEST_ASSERT_EQUAL_UINT8(8u, got.pole_pairs);
  TEST_ASSERT_EQUAL_UINT16(304u, got.resistance_mohm);
  TEST_ASSERT_EQUAL_UINT16(231u, got.inductance_uh);
  TEST_ASSERT_EQUAL_UINT8(200u, got.electrical_offset);
  /* the interlock's refusals need Status's fifth bit; Stored sits above it */
  const pour_can_calibration_result_t hi = {.status = POUR_CAN_CAL_REFUSED_NO_SENSORS, .stored = POUR_CAN_CAL_WRITE_FAILED};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_calibration_result(2, &hi, &f));
  TEST_ASSERT_EQUAL_HEX8(0xB2u, f.data[0]); /* 18 | 5 << 5 */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&f, &got));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NO_SENSORS, got.status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_WRITE_FAILED, got.stored);
  const pour_can_calibration_result_t read = {.status = POUR_CAN_CAL_STORED, .stored = POUR_CAN_CAL_CORRUPT};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_calibration_result(2, &read, &f));
  TEST_ASSERT_EQUAL_HEX8(0x53u, f.data[0]); /* the read's answer: 19 | 2 << 5 */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&f, &got));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_STORED, got.status);
  f.data[0] = 20u; /* a status beyond the last */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_calibration_result(&f, &got));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_calibration_result(2, &r, &f));
  pour_can_calibration_result_t bad = r;
  bad.status = POUR_CAN_CAL_STATUS_MAX + 1u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_calibration_result(2, &bad, &f));
  f.data[2] = 33u; /* pole pairs beyond 32 */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_calibration_result(&f, &got));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(2, POUR_CAN_CMD_CALIBRATION_START, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_command(&f, POUR_CAN_CMD_CALIBRATION_START));
}

static void test_can_drive_telemetry_CarriesOnlyTheNamedDriveFaults(void) {
  const pour_can_drive_telemetry_t t = {
      .id_2ma = -32767, .iq_2ma = 2500, .vbus_mv = 24100u, .drive_faults = 0xF902u, .crystal_4mhz = 6u};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_drive_telemetry(0, &t, &f));
  pour_can_drive_telemetry_t got;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_drive_telemetry(&f, &got));
  TEST_ASSERT_EQUAL_INT16(-32767, got.id_2ma);
  TEST_ASSERT_EQUAL_INT16(2500, got.iq_2ma);
  TEST_ASSERT_EQUAL_UINT16(24100u, got.vbus_mv);
  TEST_ASSERT_EQUAL_HEX16(0x0102u, got.drive_faults); /* bits beyond the 11 named ones are not carried */
  TEST_ASSERT_EQUAL_UINT8(6u, got.crystal_4mhz);        /* 24 MHz, beside them */
  pour_can_drive_telemetry_t bad = t;
  bad.iq_2ma = INT16_MIN;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_drive_telemetry(0, &bad, &f));
  bad = t;
  bad.crystal_4mhz = POUR_CAN_CRYSTAL_MAX + 1u; /* 52 MHz: no crystal the clock set-up takes */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_pack_drive_telemetry(0, &bad, &f));
  f.data[7] = (uint8_t)((f.data[7] & ~0x78u) | 0x68u); /* Crystal (bits 59..62) raw 13 */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_unpack_drive_telemetry(&f, &got));
}

static void test_can_classify_SeparatesNodesCmdsAndDlcs(void) {
  const uint32_t accept = 1u << POUR_CAN_CMD_SENSORS;
  pour_can_frame_t f = {.id = pour_can_id(4, POUR_CAN_CMD_SENSORS), .dlc = 8, .data = {0}};
  uint8_t cmd = 0xFF;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_classify(&f, 4, accept, &cmd));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CMD_SENSORS, cmd);
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
  RUN_TEST(test_can_pack_sensors_IsLittleEndianWithSignedScales);
  RUN_TEST(test_can_sensors_RoundTripRangeEdges);
  RUN_TEST(test_can_pack_RefusesOutOfRangeAndLeavesFrame);
  RUN_TEST(test_can_unpack_sensors_RejectsTheScaleOverloadCode);
  RUN_TEST(test_can_torque_RoundTripsFullQ15Range);
  RUN_TEST(test_can_heartbeat_CarriesOnlyNamedFaultBits);
  RUN_TEST(test_can_unpack_RejectsWrongDlcAndWrongCmd);
  RUN_TEST(test_can_identity_RoundTripsHashScaleVersionAndNegativeStatus);
  RUN_TEST(test_can_calibration_result_RoundTripsAndNamesTheReason);
  RUN_TEST(test_can_drive_telemetry_CarriesOnlyTheNamedDriveFaults);
  RUN_TEST(test_can_classify_SeparatesNodesCmdsAndDlcs);
  return UNITY_END();
}
