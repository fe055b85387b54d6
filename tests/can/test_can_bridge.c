/* SPDX-License-Identifier: MIT */
/* can_bridge's mapping between LCM messages and CAN frames, without sockets. */
#include <math.h>
#include <string.h>

#include "bridge.h"
#include "unity.h"

static pour_bridge_t b;

void setUp(void) {
  pour_bridge_config_t c = pour_bridge_default_config();
  c.node_id = 2;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_bridge_init(&b, &c));
}

void tearDown(void) {}

static pour_sensor_sample_t sample(int64_t seq, int32_t encoder) {
  pour_sensor_sample_t m;
  memset(&m, 0, sizeof m);
  m.utime = 1000 * seq + 7;
  m.seq = seq;
  m.episode = 3;
  m.encoder = encoder;
  m.scale_rotating_g = 7725;
  m.scale_target_g = -12;
  return m;
}

static void test_bridge_init_RejectsBadConfig(void) {
  pour_bridge_config_t c = pour_bridge_default_config();
  c.node_id = 64;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_bridge_init(&b, &c));
  c = pour_bridge_default_config();
  c.n_actions = 17;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_bridge_init(&b, &c));
}

static void test_bridge_SampleBecomesOneFrameWithTheReadingsAsTheyAre(void) {
  pour_can_frame_t f[1];
  const pour_sensor_sample_t m = sample(70000, 130000);
  TEST_ASSERT_EQUAL_INT(1, pour_bridge_from_sensors(&b, &m, f, NULL));
  pour_can_sensors_t s;
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(2, POUR_CAN_CMD_SENSORS), f[0].id);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_sensors(&f[0], &s));
  TEST_ASSERT_EQUAL_UINT8(70000 & 0xFF, s.seq_low);
  TEST_ASSERT_EQUAL_UINT32(130000u, s.encoder);
  TEST_ASSERT_EQUAL_INT16(7725, s.scale_rotating_g);
  TEST_ASSERT_EQUAL_INT16(-12, s.scale_target_g);
  TEST_ASSERT_EQUAL_INT64(1, b.counters.states_sent);
}

/* What the frame cannot carry is refused with the reading named, not wrapped into another value. */
static void test_bridge_RefusesReadingsTheFrameCannotCarry(void) {
  pour_can_frame_t f[1];
  const char *why = NULL;
  pour_sensor_sample_t m = sample(1, -1); /* a negative count */
  TEST_ASSERT_EQUAL_INT(0, pour_bridge_from_sensors(&b, &m, f, &why));
  TEST_ASSERT_NOT_NULL(strstr(why, "encoder"));
  m = sample(1, 1 << 24);
  TEST_ASSERT_EQUAL_INT(0, pour_bridge_from_sensors(&b, &m, f, &why));
  m = sample(1, 0);
  m.scale_rotating_g = 40000;
  TEST_ASSERT_EQUAL_INT(0, pour_bridge_from_sensors(&b, &m, f, &why));
  TEST_ASSERT_NOT_NULL(strstr(why, "scale_rotating_g"));
  m = sample(1, 0);
  m.scale_target_g = -32768; /* the frame's overload code is not a reading */
  TEST_ASSERT_EQUAL_INT(0, pour_bridge_from_sensors(&b, &m, f, &why));
  TEST_ASSERT_NOT_NULL(strstr(why, "scale_target_g"));
  TEST_ASSERT_EQUAL_INT64(4, b.counters.states_refused);
  TEST_ASSERT_EQUAL_INT64(0, b.counters.states_sent);
}

static pour_can_frame_t torque_frame(uint8_t node, uint16_t seq, q15_t torque) {
  pour_can_torque_t t = {seq, torque, 5, 1, 2};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_torque(node, &t, &f));
  return f;
}

/* The controller announces who it is: the scale of its torque and its policy. */
static void receive_identity(uint16_t tau_max_cnm, uint32_t hash) {
  const pour_can_identity_t id = {hash, tau_max_cnm, 2u, 0};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_identity(2, &id, &f));
  pour_torque_t tq;
  pour_controller_status_t st;
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_NONE, pour_bridge_from_frame(&b, &f, 0, &tq, &st));
}

static void test_bridge_TorqueAnswersTheSampleItMatches(void) {
  receive_identity(4000u, 0x12345678u); /* 40 N·m */
  pour_can_frame_t f[1];
  const pour_sensor_sample_t m = sample(70000, 5000);
  pour_bridge_from_sensors(&b, &m, f, NULL);
  pour_torque_t tq;
  pour_controller_status_t st;
  const pour_can_frame_t tf = torque_frame(2, 70000 & 0xFFFF, -16384);
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_TORQUE, pour_bridge_from_frame(&b, &tf, 123, &tq, &st));
  TEST_ASSERT_EQUAL_INT64(70000, tq.seq);
  TEST_ASSERT_EQUAL_INT32(3, tq.episode);
  TEST_ASSERT_EQUAL_INT64(m.utime, tq.state_utime);
  TEST_ASSERT_EQUAL_INT64(123, tq.utime);
  TEST_ASSERT_EQUAL_INT16(-16384, tq.torque_q15);
  TEST_ASSERT_EQUAL_DOUBLE(-20.0, tq.torque);
  TEST_ASSERT_EQUAL_INT8(5, tq.action);
  TEST_ASSERT_EQUAL_INT8(1, tq.mode);
  TEST_ASSERT_EQUAL_INT8(11, tq.n_actions);
  TEST_ASSERT_EQUAL_INT32(0x12345678, tq.weights_hash);
}

/* A controller that joined mid-run counts from the first Sensors.Seq it saw: only the low 8 bits of its
 * echo are the host's, and they find the sample. */
static void test_bridge_MatchesTheEchoByTheFramesSeqBitsOnly(void) {
  pour_can_frame_t f[1];
  const pour_sensor_sample_t m = sample(300, 5000); /* 300 = 0x12C: Sensors.Seq 0x2C */
  pour_bridge_from_sensors(&b, &m, f, NULL);
  pour_torque_t tq;
  pour_controller_status_t st;
  const pour_can_frame_t tf = torque_frame(2, 0x002C, 100); /* its count began at 0x2C */
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_TORQUE, pour_bridge_from_frame(&b, &tf, 0, &tq, &st));
  TEST_ASSERT_EQUAL_INT64(300, tq.seq);
  TEST_ASSERT_EQUAL_INT64(m.utime, tq.state_utime);
}

/* No scale is guessed: before the controller's Identity frame the torque in N·m is unknown (NaN). */
static void test_bridge_TorqueScaleComesFromTheBusOnly(void) {
  pour_can_frame_t f[1];
  const pour_sensor_sample_t m = sample(5, 5000);
  pour_bridge_from_sensors(&b, &m, f, NULL);
  pour_torque_t tq;
  pour_controller_status_t st;
  const pour_can_frame_t tf = torque_frame(2, 5, 16384);
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_TORQUE, pour_bridge_from_frame(&b, &tf, 0, &tq, &st));
  TEST_ASSERT_TRUE(isnan(tq.torque));
  TEST_ASSERT_EQUAL_INT32(0, tq.weights_hash);
  receive_identity(2000u, 7u); /* 20 N·m, the shipped policy's */
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_TORQUE, pour_bridge_from_frame(&b, &tf, 0, &tq, &st));
  TEST_ASSERT_EQUAL_DOUBLE(10.0, tq.torque);
  TEST_ASSERT_EQUAL_INT32(7, tq.weights_hash);
}

static void test_bridge_DropsTorqueForASampleNeverSent(void) {
  pour_torque_t tq;
  pour_controller_status_t st;
  const pour_can_frame_t tf = torque_frame(2, 9, 100);
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_DROPPED, pour_bridge_from_frame(&b, &tf, 0, &tq, &st));
  TEST_ASSERT_EQUAL_INT64(1, b.counters.torques_unmatched);
}

static void test_bridge_HeartbeatBecomesStatus(void) {
  pour_can_heartbeat_t hb = {2, 0x0101, 17, 4, 9, 3, 0};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_heartbeat(2, &hb, &f));
  pour_torque_t tq;
  pour_controller_status_t st;
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_STATUS, pour_bridge_from_frame(&b, &f, 55, &tq, &st));
  TEST_ASSERT_EQUAL_INT8(2, st.mode);
  TEST_ASSERT_EQUAL_INT16(0x0101, st.faults);
  TEST_ASSERT_EQUAL_INT64(17, st.messages_dropped);
  TEST_ASSERT_EQUAL_INT64(4, st.overruns);
  TEST_ASSERT_EQUAL_INT64(55, st.utime);
  TEST_ASSERT_EQUAL_INT64(1, st.tick);
}

static void test_bridge_IgnoresOtherNodesAndHostFramesButDropsMalformed(void) {
  pour_torque_t tq;
  pour_controller_status_t st;
  pour_can_frame_t f = torque_frame(3, 0, 0); /* node 3 */
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_NONE, pour_bridge_from_frame(&b, &f, 0, &tq, &st));
  pour_can_frame_t own[1];
  const pour_sensor_sample_t m = sample(1, 0);
  pour_bridge_from_sensors(&b, &m, own, NULL); /* our own Sensors frame, seen on the bus */
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_NONE, pour_bridge_from_frame(&b, &own[0], 0, &tq, &st));
  f = torque_frame(2, 1, 0);
  f.dlc = 6;
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_DROPPED, pour_bridge_from_frame(&b, &f, 0, &tq, &st));
  f.id = pour_can_id(2, 0x1F);
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_DROPPED, pour_bridge_from_frame(&b, &f, 0, &tq, &st));
  TEST_ASSERT_EQUAL_INT64(2, b.counters.frames_dropped);
}

static void test_bridge_CommandBecomesEstopAndClear(void) {
  pour_command_t c = {0, 1, 1, 0, 0};
  pour_can_frame_t f[4];
  TEST_ASSERT_EQUAL_INT(2, pour_bridge_from_command(&b, &c, f));
  pour_can_estop_t e;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_estop(&f[0], &e));
  TEST_ASSERT_EQUAL_UINT8(1, e.assert_estop);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_command(&f[1], POUR_CAN_CMD_CLEAR_ERRORS));
  c.stop = 1;
  c.reset = 1;
  TEST_ASSERT_EQUAL_INT(4, pour_bridge_from_command(&b, &c, f)); /* in the order the core acts on them */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_command(&f[1], POUR_CAN_CMD_STOP));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_command(&f[2], POUR_CAN_CMD_CLEAR_ERRORS));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_command(&f[3], POUR_CAN_CMD_RESET));
  c.estop = 0;
  c.clear_faults = 0;
  c.stop = 0;
  c.reset = 0;
  TEST_ASSERT_EQUAL_INT(1, pour_bridge_from_command(&b, &c, f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_estop(&f[0], &e));
  TEST_ASSERT_EQUAL_UINT8(0, e.assert_estop);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_bridge_init_RejectsBadConfig);
  RUN_TEST(test_bridge_SampleBecomesOneFrameWithTheReadingsAsTheyAre);
  RUN_TEST(test_bridge_RefusesReadingsTheFrameCannotCarry);
  RUN_TEST(test_bridge_TorqueAnswersTheSampleItMatches);
  RUN_TEST(test_bridge_MatchesTheEchoByTheFramesSeqBitsOnly);
  RUN_TEST(test_bridge_TorqueScaleComesFromTheBusOnly);
  RUN_TEST(test_bridge_DropsTorqueForASampleNeverSent);
  RUN_TEST(test_bridge_HeartbeatBecomesStatus);
  RUN_TEST(test_bridge_IgnoresOtherNodesAndHostFramesButDropsMalformed);
  RUN_TEST(test_bridge_CommandBecomesEstopAndClear);
  return UNITY_END();
}
