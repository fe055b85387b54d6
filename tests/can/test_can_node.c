/* SPDX-License-Identifier: MIT */
/* CAN node: frames -> control input, watchdog, heartbeat schedule, dropped-frame accounting. */
#include <string.h>

#include "pour/can_node.h"
#include "unity.h"

static pour_can_node_t node;
static pour_can_node_config_t cfg;

void setUp(void) {
  cfg = pour_can_node_default_config();
  cfg.node_id = 3;
  cfg.watchdog_ms = 5;
  cfg.heartbeat_period_ms = 4;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &cfg));
}

void tearDown(void) {}

static void send_state(uint16_t seq, int32_t theta) {
  pour_can_state_a_t a = {.theta_urad = theta, .omega_urad_s = -5, .seq_low = (uint8_t)(seq & 0xFFu)};
  pour_can_state_b_t b = {.seq = seq, .v_rotating = 30000, .v_target = 100, .v_spill = 7};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_a(cfg.node_id, &a, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_b(cfg.node_id, &b, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
}

/* One tick with a stand-in controller output that holds the given torque in RUN. */
static uint8_t tick(q15_t torque, pour_control_input_t *in, pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX]) {
  pour_can_node_begin_tick(&node, in);
  pour_control_output_t out;
  memset(&out, 0, sizeof out);
  out.torque = in->estop ? 0 : torque;
  out.mode = (uint8_t)(in->estop ? POUR_MODE_ESTOP : POUR_MODE_RUN);
  out.action = 4;
  return pour_can_node_end_tick(&node, &out, 9, tx);
}

static void test_can_node_init_RejectsBadConfig(void) {
  pour_can_node_config_t bad = cfg;
  bad.node_id = 64;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(&node, &bad));
  bad = cfg;
  bad.watchdog_ms = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(&node, &bad));
  bad = cfg;
  bad.heartbeat_period_ms = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(&node, &bad));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(NULL, &cfg));
}

static void test_can_node_StatePairBecomesOneFreshInput(void) {
  send_state(0x1234, 1500000);
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  tick(100, &in, tx);
  TEST_ASSERT_TRUE(in.state_fresh);
  TEST_ASSERT_EQUAL_UINT32(0x1234, in.state.seq);
  TEST_ASSERT_EQUAL_INT32(1500000, in.state.theta_urad);
  TEST_ASSERT_EQUAL_INT32(-5, in.state.omega_urad_s);
  TEST_ASSERT_EQUAL_INT16(30000, in.state.v_rotating);
  TEST_ASSERT_EQUAL_INT16(7, in.state.v_spill);
  tick(100, &in, tx);
  TEST_ASSERT_FALSE(in.state_fresh);
}

static void test_can_node_TorqueFrameEchoesSeqEveryTick(void) {
  send_state(77, 0);
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  uint8_t n = tick(-1234, &in, tx);
  TEST_ASSERT_EQUAL_UINT8(2, n); /* torque + first heartbeat */
  pour_can_torque_t t;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &t));
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(3, POUR_CAN_CMD_TORQUE), tx[0].id);
  TEST_ASSERT_EQUAL_UINT16(77, t.seq);
  TEST_ASSERT_EQUAL_INT16(-1234, t.torque);
  TEST_ASSERT_EQUAL_UINT8(4, t.action);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, t.mode);
}

static void test_can_node_HeartbeatAtConfiguredPeriod(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  unsigned heartbeats = 0;
  uint8_t last_counter = 0;
  for (unsigned t = 0; t < 12; ++t) {
    send_state((uint16_t)t, 0);
    uint8_t n = tick(0, &in, tx);
    if (n == 2) {
      pour_can_heartbeat_t hb;
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[1], &hb));
      TEST_ASSERT_EQUAL_UINT(0, t % 4u);
      TEST_ASSERT_EQUAL_UINT16(9, hb.overruns);
      last_counter = hb.counter;
      ++heartbeats;
    }
  }
  TEST_ASSERT_EQUAL_UINT(3, heartbeats);
  TEST_ASSERT_EQUAL_UINT8(2, last_counter);
}

static void test_can_node_SilenceTripsWatchdogAfterTimeout(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  for (unsigned t = 0; t < 20; ++t) { /* not armed before the first valid frame */
    tick(1000, &in, tx);
    TEST_ASSERT_EQUAL_HEX16(0, node.faults);
  }
  send_state(1, 0);
  for (unsigned t = 0; t < 5; ++t) {
    tick(1000, &in, tx);
    pour_can_torque_t tq;
    TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
    TEST_ASSERT_EQUAL_INT16(1000, tq.torque);
  }
  tick(1000, &in, tx); /* 6 ms without a valid frame > 5 ms */
  pour_can_torque_t tq;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
  TEST_ASSERT_EQUAL_INT16(0, tq.torque);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, tq.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_CAN_FAULT_WATCHDOG, node.faults);
  /* Latched: a fresh state does not clear it, ClearErrors does. */
  send_state(2, 0);
  tick(1000, &in, tx);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
  TEST_ASSERT_EQUAL_INT16(0, tq.torque);
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_clear_errors(cfg.node_id, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  tick(1000, &in, tx);
  TEST_ASSERT_TRUE(in.clear_faults);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
  TEST_ASSERT_EQUAL_INT16(1000, tq.torque);
  tick(1000, &in, tx);
  TEST_ASSERT_FALSE(in.clear_faults); /* one-shot */
}

static void test_can_node_HeartbeatReportsWatchdogFault(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  send_state(1, 0);
  pour_can_heartbeat_t hb = {0};
  for (unsigned t = 0; t < 12; ++t) {
    if (tick(0, &in, tx) == 2) {
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[1], &hb));
    }
  }
  TEST_ASSERT_EQUAL_HEX16(POUR_CAN_FAULT_WATCHDOG, hb.faults & POUR_CAN_FAULT_WATCHDOG);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, hb.mode);
}

static void test_can_node_EstopLevelReachesTheNextTick(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  send_state(1, 0);
  tick(5000, &in, tx);
  pour_can_frame_t f;
  pour_can_estop_t e = {.assert_estop = 1};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  tick(5000, &in, tx);
  TEST_ASSERT_TRUE(in.estop);
  pour_can_torque_t tq;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
  TEST_ASSERT_EQUAL_INT16(0, tq.torque);
  tick(5000, &in, tx);
  TEST_ASSERT_TRUE(in.estop); /* a level, not a pulse */
  e.assert_estop = 0;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  tick(5000, &in, tx);
  TEST_ASSERT_FALSE(in.estop);
}

static void test_can_node_MalformedFramesAreDroppedAndCounted(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  send_state(1, 42);
  tick(0, &in, tx);
  pour_can_frame_t f;
  /* wrong DLC */
  pour_can_state_a_t a = {.theta_urad = 999, .omega_urad_s = 0, .seq_low = 2};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_a(cfg.node_id, &a, &f));
  f.dlc = 6;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_node_receive(&node, &f));
  /* unknown cmd, and a cmd only the controller sends */
  f.id = pour_can_id(cfg.node_id, 0x1F);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  pour_can_torque_t t = {0};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_torque(cfg.node_id, &t, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  /* out-of-range theta */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_a(cfg.node_id, &a, &f));
  f.data[2] = 0x7F;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_node_receive(&node, &f));
  /* StateB without its StateA */
  pour_can_state_b_t b = {.seq = 2, .v_rotating = 1, .v_target = 1, .v_spill = 1};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_b(cfg.node_id, &b, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_UNPAIRED, pour_can_node_receive(&node, &f));
  /* another node's state: ignored, not an error */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_state_a(7, &a, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OTHER_NODE, pour_can_node_receive(&node, &f));

  TEST_ASSERT_EQUAL_UINT32(1, node.counters.bad_dlc);
  TEST_ASSERT_EQUAL_UINT32(2, node.counters.bad_id);
  TEST_ASSERT_EQUAL_UINT32(1, node.counters.out_of_range);
  TEST_ASSERT_EQUAL_UINT32(1, node.counters.unpaired);
  TEST_ASSERT_EQUAL_UINT32(1, node.counters.other_node);
  TEST_ASSERT_EQUAL_UINT32(5, pour_can_node_dropped(&node));
  tick(0, &in, tx);
  TEST_ASSERT_FALSE(in.state_fresh);
  TEST_ASSERT_EQUAL_INT32(42, in.state.theta_urad); /* nothing of the bad frames got through */
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_can_node_init_RejectsBadConfig);
  RUN_TEST(test_can_node_StatePairBecomesOneFreshInput);
  RUN_TEST(test_can_node_TorqueFrameEchoesSeqEveryTick);
  RUN_TEST(test_can_node_HeartbeatAtConfiguredPeriod);
  RUN_TEST(test_can_node_SilenceTripsWatchdogAfterTimeout);
  RUN_TEST(test_can_node_HeartbeatReportsWatchdogFault);
  RUN_TEST(test_can_node_EstopLevelReachesTheNextTick);
  RUN_TEST(test_can_node_MalformedFramesAreDroppedAndCounted);
  return UNITY_END();
}
