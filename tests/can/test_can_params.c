/* SPDX-License-Identifier: MIT */
/* Parameter requests over CAN: the node takes them (bad frames dropped and counted, one at a time), and
 * pour_can_params_handle answers each with ParamValue or a ParamAck that names the reason. */
#include <string.h>

#include "pour/can_params.h"
#include "pour/weights_compiled.h"
#include "unity.h"

#define NODE 4u

static pour_can_node_t node;
static pour_params_t params;
static pour_control_t ctl;
static pour_can_params_env_t env;
static int saves;
static bool save_fails;

static pour_status_t apply(void *user, const pour_params_t *candidate) {
  (void)user;
  return pour_params_apply(&ctl, candidate, &pour_weights_compiled);
}

static pour_status_t save(void *user, const pour_params_t *p) {
  (void)user;
  (void)p;
  saves++;
  return save_fails ? POUR_EINVAL : POUR_OK;
}

void setUp(void) {
  pour_can_node_config_t nc = pour_can_node_default_config();
  nc.node_id = NODE;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &nc));
  const pour_control_config_t c = pour_control_default_config();
  pour_params_default(&params, &c, NODE);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &c, &pour_weights_compiled));
  memset(&env, 0, sizeof env);
  env.writable = true;
  env.apply = apply;
  env.save = save;
  saves = 0;
  save_fails = false;
}

void tearDown(void) {}

static pour_can_frame_t raw(uint8_t cmd, uint8_t dlc, const uint8_t *data) {
  pour_can_frame_t f;
  memset(&f, 0, sizeof f);
  f.id = pour_can_id(NODE, cmd);
  f.dlc = dlc;
  if (dlc > 0u) {
    memcpy(f.data, data, dlc);
  }
  return f;
}

/* Sends a request frame through the node and answers it; returns the result, *reply the answer. */
static pour_param_result_t ask(const pour_can_frame_t *f, pour_can_frame_t *reply) {
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, f));
  pour_can_param_request_t r;
  TEST_ASSERT_TRUE(pour_can_node_take_param_request(&node, &r));
  TEST_ASSERT_FALSE(pour_can_node_take_param_request(&node, &r));
  return pour_can_params_handle(NODE, &r, &params, &env, reply);
}

static pour_param_result_t write_param(uint8_t id, int32_t value, pour_can_frame_t *reply) {
  const pour_can_param_t m = {.param_id = id, .value = value};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_param(NODE, POUR_CAN_CMD_PARAM_WRITE, &m, &f));
  return ask(&f, reply);
}

static void assert_ack(const pour_can_frame_t *reply, uint8_t request, uint8_t id, pour_param_result_t result) {
  pour_can_param_ack_t a;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_param_ack(reply, &a));
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(NODE, POUR_CAN_CMD_PARAM_ACK), reply->id);
  TEST_ASSERT_EQUAL_UINT8(request, a.request);
  TEST_ASSERT_EQUAL_UINT8(id, a.param_id);
  TEST_ASSERT_EQUAL_UINT8((uint8_t)result, a.result);
}

static void assert_value(const pour_can_frame_t *reply, uint8_t id, int32_t value) {
  pour_can_param_t v;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_param(reply, POUR_CAN_CMD_PARAM_VALUE, &v));
  TEST_ASSERT_EQUAL_UINT8(id, v.param_id);
  TEST_ASSERT_EQUAL_INT32(value, v.value);
}

static void test_can_params_node_DropsAndCountsBadFrames(void) {
  const uint8_t d[8] = {0};
  pour_can_frame_t f = raw(POUR_CAN_CMD_PARAM_WRITE, 4, d); /* one byte short */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_node_receive(&node, &f));
  f = raw(POUR_CAN_CMD_PARAM_READ, 0, d);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_node_receive(&node, &f));
  f = raw(POUR_CAN_CMD_PARAM_SAVE, 1, d);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_node_receive(&node, &f));
  f = raw(POUR_CAN_CMD_TARE, 1, d); /* no scale named */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_node_receive(&node, &f));
  const uint8_t four[1] = {4};
  f = raw(POUR_CAN_CMD_TARE, 1, four);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_node_receive(&node, &f));
  f = raw(POUR_CAN_CMD_PARAM_ACK, 3, d); /* our own transmissions */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  f = raw(POUR_CAN_CMD_PARAM_VALUE, 5, d);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  f = raw(0x11, 0, d); /* reserved */
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  pour_can_param_request_t r;
  TEST_ASSERT_FALSE(pour_can_node_take_param_request(&node, &r));
  TEST_ASSERT_EQUAL_UINT32(8u, pour_can_node_dropped(&node));
  TEST_ASSERT_FALSE(node.armed); /* parameter traffic is not the control link */
}

static void test_can_params_node_TakesOneRequestAtATime(void) {
  const uint8_t d[1] = {3};
  pour_can_frame_t f = raw(POUR_CAN_CMD_PARAM_READ, 1, d);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BUSY, pour_can_node_receive(&node, &f));
  TEST_ASSERT_EQUAL_UINT32(1u, node.counters.param_busy);
  TEST_ASSERT_EQUAL_UINT32(1u, pour_can_node_dropped(&node));
  pour_can_param_request_t r;
  TEST_ASSERT_TRUE(pour_can_node_take_param_request(&node, &r));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CMD_PARAM_READ, r.cmd);
  TEST_ASSERT_EQUAL_UINT8(3u, r.param_id);
}

static void test_can_params_ReadAnswersTheValueOrRefusesAnUnknownId(void) {
  pour_can_frame_t reply;
  const uint8_t id[1] = {POUR_PARAM_ID_theta_max};
  pour_can_frame_t f = raw(POUR_CAN_CMD_PARAM_READ, 1, id);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, ask(&f, &reply));
  assert_value(&reply, POUR_PARAM_ID_theta_max, params.control.safety.theta_max_urad);
  const uint8_t unknown[1] = {200};
  f = raw(POUR_CAN_CMD_PARAM_READ, 1, unknown);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_UNKNOWN_ID, ask(&f, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_READ, 200, POUR_PARAM_UNKNOWN_ID);
}

static void test_can_params_WriteAppliesOrRefusesWithItsId(void) {
  pour_can_frame_t reply;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, write_param(POUR_PARAM_ID_omega_max, 1200000, &reply));
  assert_value(&reply, POUR_PARAM_ID_omega_max, 1200000);
  TEST_ASSERT_EQUAL_INT32(1200000, ctl.config.safety.omega_max_urad_s); /* in force in the core */
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, write_param(POUR_PARAM_ID_encoder_bits, 7, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_WRITE, POUR_PARAM_ID_encoder_bits, POUR_PARAM_OUT_OF_RANGE);
  /* 100 rad/s fits the int32 and the old table: the safety case's 2 rad/s refuses it on the node. */
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, write_param(POUR_PARAM_ID_omega_max, 99999999, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_WRITE, POUR_PARAM_ID_omega_max, POUR_PARAM_OUT_OF_RANGE);
  TEST_ASSERT_EQUAL_INT32(1200000, ctl.config.safety.omega_max_urad_s); /* the core keeps what it had */
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_UNKNOWN_ID, write_param(99, 1, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_WRITE, 99, POUR_PARAM_UNKNOWN_ID);
  /* In range, but the core refuses theta_min >= theta_max: nothing changes. */
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_INCONSISTENT,
                        write_param(POUR_PARAM_ID_theta_min, params.control.safety.theta_max_urad, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_WRITE, POUR_PARAM_ID_theta_min, POUR_PARAM_INCONSISTENT);
  TEST_ASSERT_EQUAL_INT32(pour_control_default_config().safety.theta_min_urad, params.control.safety.theta_min_urad);
  env.writable = false;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_BUSY, write_param(POUR_PARAM_ID_omega_max, 900000, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_WRITE, POUR_PARAM_ID_omega_max, POUR_PARAM_BUSY);
  TEST_ASSERT_EQUAL_INT32(1200000, params.control.safety.omega_max_urad_s);
}

static void test_can_params_SaveReportsTheStorage(void) {
  pour_can_frame_t reply;
  pour_can_frame_t f = raw(POUR_CAN_CMD_PARAM_SAVE, 0, NULL);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, ask(&f, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_SAVE, 0, POUR_PARAM_OK);
  TEST_ASSERT_EQUAL_INT(1, saves);
  env.writable = false; /* RUN, ESTOP or the active stop: BUSY, nothing stored */
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_BUSY, ask(&f, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_SAVE, 0, POUR_PARAM_BUSY);
  TEST_ASSERT_EQUAL_INT(1, saves);
  env.writable = true;
  save_fails = true;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_NO_STORAGE, ask(&f, &reply));
  env.save = NULL;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_NO_STORAGE, ask(&f, &reply));
  assert_ack(&reply, POUR_CAN_CMD_PARAM_SAVE, 0, POUR_PARAM_NO_STORAGE);
}

static void test_can_params_TareAndZeroTakeTheLatestRawSample(void) {
  pour_can_frame_t reply;
  const uint8_t both[1] = {POUR_CAN_TARE_ROTATING | POUR_CAN_TARE_TARGET};
  pour_can_frame_t tare = raw(POUR_CAN_CMD_TARE, 1, both);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_NO_SAMPLE, ask(&tare, &reply));
  assert_ack(&reply, POUR_CAN_CMD_TARE, 0, POUR_PARAM_NO_SAMPLE);
  env.have_sample = true;
  env.sample.encoder = 1234;
  env.sample.scale_rotating_g = 2500;
  env.sample.scale_target_g = -40;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, ask(&tare, &reply));
  assert_ack(&reply, POUR_CAN_CMD_TARE, 0, POUR_PARAM_OK);
  TEST_ASSERT_EQUAL_INT32(2500, params.scale_rotating_tare_g);
  TEST_ASSERT_EQUAL_INT32(-40, params.scale_target_tare_g);
  pour_can_frame_t zero = raw(POUR_CAN_CMD_ZERO, 0, NULL);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, ask(&zero, &reply));
  TEST_ASSERT_EQUAL_INT32(1234, params.encoder_zero);
  pour_sensors_t s = env.sample;
  pour_params_correct(&params, &s);
  TEST_ASSERT_EQUAL_UINT32(0u, s.encoder);
  TEST_ASSERT_EQUAL_INT32(0, s.scale_rotating_g);
  TEST_ASSERT_EQUAL_INT32(0, s.scale_target_g);
  env.writable = false;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_BUSY, ask(&zero, &reply));
  assert_ack(&reply, POUR_CAN_CMD_ZERO, 0, POUR_PARAM_BUSY);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_can_params_node_DropsAndCountsBadFrames);
  RUN_TEST(test_can_params_node_TakesOneRequestAtATime);
  RUN_TEST(test_can_params_ReadAnswersTheValueOrRefusesAnUnknownId);
  RUN_TEST(test_can_params_WriteAppliesOrRefusesWithItsId);
  RUN_TEST(test_can_params_SaveReportsTheStorage);
  RUN_TEST(test_can_params_TareAndZeroTakeTheLatestRawSample);
  return UNITY_END();
}
