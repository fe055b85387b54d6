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

static pour_plant_state_t state(int64_t seq, double theta) {
  pour_plant_state_t m;
  memset(&m, 0, sizeof m);
  m.utime = 1000 * seq + 7;
  m.seq = seq;
  m.episode = 3;
  m.theta = theta;
  m.omega = -0.25;
  m.v_rotating = 0.75;
  m.v_target = 0.2;
  m.v_spill = 0.05;
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

static void test_bridge_StateBecomesTwoFramesInFixedPoint(void) {
  pour_can_frame_t f[2];
  const pour_plant_state_t m = state(70000, 1.25);
  TEST_ASSERT_EQUAL_INT(2, pour_bridge_from_state(&b, &m, f));
  pour_can_state_a_t a;
  pour_can_state_b_t sb;
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(2, POUR_CAN_CMD_STATE_A), f[0].id);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_state_a(&f[0], &a));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_state_b(&f[1], &sb));
  TEST_ASSERT_EQUAL_INT32(1250000, a.theta_urad);
  TEST_ASSERT_EQUAL_INT32(-250000, a.omega_urad_s);
  TEST_ASSERT_EQUAL_UINT16(70000 & 0xFFFF, sb.seq);
  TEST_ASSERT_EQUAL_UINT8(70000 & 0xFF, a.seq_low);
  TEST_ASSERT_EQUAL_INT16(24576, sb.v_rotating);
  TEST_ASSERT_EQUAL_INT16(6554, sb.v_target); /* round(0.2 * 32768) */
}

static void test_bridge_RefusesStatesOutsideTheCanRange(void) {
  pour_can_frame_t f[2];
  const pour_plant_state_t m = state(1, 3.5); /* > 3.2 rad */
  TEST_ASSERT_EQUAL_INT(0, pour_bridge_from_state(&b, &m, f));
  TEST_ASSERT_EQUAL_INT64(1, b.counters.states_refused);
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

static void test_bridge_TorqueAnswersTheStateItMatches(void) {
  receive_identity(4000u, 0x12345678u); /* 40 N·m */
  pour_can_frame_t f[2];
  const pour_plant_state_t m = state(70000, 0.5);
  pour_bridge_from_state(&b, &m, f);
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

/* No scale is guessed: before the controller's Identity frame the torque in N·m is unknown (NaN). */
static void test_bridge_TorqueScaleComesFromTheBusOnly(void) {
  pour_can_frame_t f[2];
  const pour_plant_state_t m = state(5, 0.5);
  pour_bridge_from_state(&b, &m, f);
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

static void test_bridge_DropsTorqueForAStateNeverSent(void) {
  pour_torque_t tq;
  pour_controller_status_t st;
  const pour_can_frame_t tf = torque_frame(2, 9, 100);
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_DROPPED, pour_bridge_from_frame(&b, &tf, 0, &tq, &st));
  TEST_ASSERT_EQUAL_INT64(1, b.counters.torques_unmatched);
}

static void test_bridge_HeartbeatBecomesStatus(void) {
  pour_can_heartbeat_t hb = {2, 0x0101, 17, 4, 9};
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
  pour_can_frame_t two[2];
  const pour_plant_state_t m = state(1, 0.0);
  pour_bridge_from_state(&b, &m, two); /* our own StateA, seen on the bus */
  TEST_ASSERT_EQUAL_INT(POUR_BRIDGE_NONE, pour_bridge_from_frame(&b, &two[0], 0, &tq, &st));
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
  RUN_TEST(test_bridge_StateBecomesTwoFramesInFixedPoint);
  RUN_TEST(test_bridge_RefusesStatesOutsideTheCanRange);
  RUN_TEST(test_bridge_TorqueAnswersTheStateItMatches);
  RUN_TEST(test_bridge_TorqueScaleComesFromTheBusOnly);
  RUN_TEST(test_bridge_DropsTorqueForAStateNeverSent);
  RUN_TEST(test_bridge_HeartbeatBecomesStatus);
  RUN_TEST(test_bridge_IgnoresOtherNodesAndHostFramesButDropsMalformed);
  RUN_TEST(test_bridge_CommandBecomesEstopAndClear);
  return UNITY_END();
}
