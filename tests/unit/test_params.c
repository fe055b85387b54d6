/* SPDX-License-Identifier: MIT */
/* The parameter table: ids, ranges, the sample correction, the storage blob and putting a set in force. */
#include <string.h>

#include "pour/params.h"
#include "pour/weights_compiled.h"
#include "unity.h"

static pour_params_t params;
static pour_control_t ctl;
static pour_control_input_t in;
static pour_control_output_t out;

void setUp(void) {
  const pour_control_config_t c = pour_control_default_config();
  pour_params_default(&params, &c, 5);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &params.control, &pour_weights_compiled));
  memset(&in, 0, sizeof in);
}

void tearDown(void) {}

static void test_params_table_IsDenseAndEveryDefaultIsInRange(void) {
  for (uint8_t id = 0; id < POUR_PARAM_COUNT; ++id) {
    const pour_param_info_t *info = pour_param_info(id);
    TEST_ASSERT_NOT_NULL(info);
    TEST_ASSERT_EQUAL_UINT8(id, info->id);
    TEST_ASSERT_TRUE(info->min <= info->max);
    int32_t v = INT32_MIN;
    TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_get(&params, id, &v));
    TEST_ASSERT_TRUE_MESSAGE(v >= info->min && v <= info->max, info->name);
  }
  TEST_ASSERT_NULL(pour_param_info((uint8_t)POUR_PARAM_COUNT));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_check(&params));
}

static void test_params_get_ReadsTheFieldsTheyLiveIn(void) {
  int32_t v = 0;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_get(&params, POUR_PARAM_ID_theta_max, &v));
  TEST_ASSERT_EQUAL_INT32(params.control.safety.theta_max_urad, v);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_get(&params, POUR_PARAM_ID_stop_timeout, &v));
  TEST_ASSERT_EQUAL_INT32(params.control.stop.timeout_ms, v);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_get(&params, POUR_PARAM_ID_node_id, &v));
  TEST_ASSERT_EQUAL_INT32(5, v);
  v = 77;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_UNKNOWN_ID, pour_params_get(&params, 200, &v));
  TEST_ASSERT_EQUAL_INT32(77, v);
}

static void test_params_set_RefusesOutOfRangeAndUnknownIds(void) {
  const pour_params_t before = params;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_tau_limit, 0));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_tau_limit, 32768));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_encoder_bits, 25));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_node_id, 64));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_UNKNOWN_ID, pour_params_set(&params, POUR_PARAM_COUNT, 1));
  TEST_ASSERT_EQUAL_MEMORY(&before, &params, sizeof params);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_stop_timeout, 65535));
  TEST_ASSERT_EQUAL_UINT16(65535u, params.control.stop.timeout_ms);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_theta_min, -87266));
  TEST_ASSERT_EQUAL_INT32(-87266, params.control.safety.theta_min_urad);
}

/* The envelope's ranges are the safety case's (docs/safety.md, "The motion envelope"), not the types': 100 rad/s
 * fits an int32 and the old table's range, and is refused; the case's own limits pass. */
static void test_params_set_RefusesAnEnvelopeBeyondTheSafetyCase(void) {
  const pour_params_t before = params;
  static const struct {
    uint8_t id;
    int32_t limit;
  } k_cases[] = {
      {POUR_PARAM_ID_omega_max, 2000000},       {POUR_PARAM_ID_omega_slack, 2000000},
      {POUR_PARAM_ID_slow_omega, 2000000},      {POUR_PARAM_ID_stop_return_speed, 2000000},
      {POUR_PARAM_ID_stop_rest_omega, 2000000}, {POUR_PARAM_ID_alpha_max, 3400000},
      {POUR_PARAM_ID_governor_gain, 16384},     {POUR_PARAM_ID_stop_gain, 16384},
      /* the supervisor's and the estimator's limits: tighter is accepted, looser is not */
      {POUR_PARAM_ID_supervisor_theta_margin, 87266}, {POUR_PARAM_ID_supervisor_omega_max, 4000000},
      {POUR_PARAM_ID_jump_max, 10000},
  };
  for (unsigned i = 0; i < sizeof k_cases / sizeof k_cases[0]; ++i) {
    TEST_ASSERT_EQUAL_INT32(k_cases[i].limit, pour_param_info(k_cases[i].id)->max);
    TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, k_cases[i].id, k_cases[i].limit + 1));
  }
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_omega_max, 99999999));
  /* the angles: from 5 deg past upright to the 135 deg hard stop */
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_theta_min, -87267));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_theta_max, 2356195));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OUT_OF_RANGE, pour_params_set(&params, POUR_PARAM_ID_theta_max, 3141593));
  TEST_ASSERT_EQUAL_MEMORY(&before, &params, sizeof params);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_omega_max, 2000000));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_governor_gain, 16384));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_supervisor_omega_max, 3000000));
  TEST_ASSERT_EQUAL_INT32(3000000, params.control.supervisor.omega_max_urad_s);
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_jump_max, 5000));
  TEST_ASSERT_EQUAL_INT32(5000, params.control.sensors.jump_max_urad);
  params = before;
}

static void test_params_check_RefusesAZeroPastTheEncodersRange(void) {
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_encoder_zero, 131071));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_check(&params));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_encoder_zero, 131072));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_INCONSISTENT, pour_params_check(&params));
}

static void test_params_correct_AppliesZeroTareAndFactor(void) {
  pour_sensors_t s = {.seq = 9, .encoder = 100, .scale_rotating_g = 1000, .scale_target_g = -3};
  pour_sensors_t same = s;
  pour_params_correct(&params, &same);
  TEST_ASSERT_EQUAL_MEMORY(&s, &same, sizeof s); /* the defaults change nothing */
  params.encoder_zero = 130000;
  params.scale_rotating_tare_g = 200;
  params.scale_rotating_factor_ppm = 1500000;
  params.scale_target_tare_g = -10;
  params.scale_target_factor_ppm = 500001; /* 7 g * 0.500001 = 3.500007: rounds up */
  pour_params_correct(&params, &s);
  TEST_ASSERT_EQUAL_UINT32(100u + 131072u - 130000u, s.encoder); /* wraps below zero */
  TEST_ASSERT_EQUAL_INT32(1200, s.scale_rotating_g);
  TEST_ASSERT_EQUAL_INT32(4, s.scale_target_g);
  s.scale_target_g = -24; /* (-24 + 10) * 0.500001 = -7.000014: symmetric rounding */
  s.encoder = 131072;     /* out of the encoder's range: left for the core to refuse */
  pour_params_correct(&params, &s);
  TEST_ASSERT_EQUAL_INT32(-7, s.scale_target_g);
  TEST_ASSERT_EQUAL_UINT32(131072u, s.encoder);
}

static void test_params_blob_RoundTrips(void) {
  uint8_t buf[POUR_PARAMS_BLOB_MAX];
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_omega_max, 1500000));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_scale_target_tare, -321));
  const uint32_t n = pour_params_serialize(&params, buf, sizeof buf);
  TEST_ASSERT_EQUAL_UINT32(POUR_PARAMS_BLOB_MAX, n);
  TEST_ASSERT_EQUAL_UINT32(0u, pour_params_serialize(&params, buf, n - 1u));
  pour_params_t back;
  const pour_control_config_t c = pour_control_default_config();
  pour_params_default(&back, &c, 0);
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_OK, pour_params_deserialize(buf, n, &back, NULL));
  for (uint8_t id = 0; id < POUR_PARAM_COUNT; ++id) {
    int32_t a = 0, b = 0;
    (void)pour_params_get(&params, id, &a);
    (void)pour_params_get(&back, id, &b);
    TEST_ASSERT_EQUAL_INT32(a, b);
  }
}

static void test_params_blob_RefusesCorruptTruncatedAndForeignBlobs(void) {
  uint8_t buf[POUR_PARAMS_BLOB_MAX];
  const uint32_t n = pour_params_serialize(&params, buf, sizeof buf);
  pour_params_t p = params;
  const pour_params_t before = p;
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_TRUNCATED, pour_params_deserialize(buf, 5, &p, NULL));
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_TRUNCATED, pour_params_deserialize(buf, n - 1u, &p, NULL));
  buf[20] ^= 0x01u; /* one bit of a value */
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_BAD_CRC, pour_params_deserialize(buf, n, &p, NULL));
  buf[20] ^= 0x01u;
  buf[0] = 'X';
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_BAD_MAGIC, pour_params_deserialize(buf, n, &p, NULL));
  (void)pour_params_serialize(&params, buf, sizeof buf);
  buf[4] = 2u;
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_BAD_VERSION, pour_params_deserialize(buf, n, &p, NULL));
  TEST_ASSERT_EQUAL_MEMORY(&before, &p, sizeof p);
  TEST_ASSERT_EQUAL_STRING("CRC mismatch (corrupt)", pour_params_blob_name(POUR_PARAMS_BLOB_BAD_CRC));
}

/* A blob with a valid CRC whose record for id carries value. */
static uint32_t blob_with(uint8_t id, int32_t value, uint8_t *buf) {
  const uint32_t n = pour_params_serialize(&params, buf, POUR_PARAMS_BLOB_MAX);
  const uint32_t at = 8u + 5u * id;
  for (int i = 0; i < 4; ++i) {
    buf[at + 1u + (uint32_t)i] = (uint8_t)(((uint32_t)value >> (8 * i)) & 0xFFu);
  }
  const uint32_t crc = pour_crc32(buf, n - 4u);
  for (int i = 0; i < 4; ++i) {
    buf[n - 4u + (uint32_t)i] = (uint8_t)((crc >> (8 * i)) & 0xFFu);
  }
  return n;
}

static void test_params_blob_NamesAValueOutOfRange(void) {
  uint8_t buf[POUR_PARAMS_BLOB_MAX];
  pour_params_t p = params;
  uint8_t bad = 0;
  uint32_t n = blob_with(POUR_PARAM_ID_encoder_bits, 30, buf);
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_BAD_VALUE, pour_params_deserialize(buf, n, &p, &bad));
  TEST_ASSERT_EQUAL_UINT8(POUR_PARAM_ID_encoder_bits, bad);
  n = blob_with(POUR_PARAM_ID_encoder_zero, 200000, buf); /* in its range, past 2^17 */
  TEST_ASSERT_EQUAL_INT(POUR_PARAMS_BLOB_BAD_VALUE, pour_params_deserialize(buf, n, &p, &bad));
  TEST_ASSERT_EQUAL_UINT8(POUR_PARAM_ID_encoder_zero, bad);
  TEST_ASSERT_EQUAL_UINT32(0xCBF43926u, pour_crc32((const uint8_t *)"123456789", 9)); /* the CRC-32 check value */
}

static void test_params_apply_InIdleChangesTheCore(void) {
  TEST_ASSERT_TRUE(pour_params_writable(&ctl));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_omega_max, 1000000));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  TEST_ASSERT_EQUAL_INT32(1000000, ctl.config.safety.omega_max_urad_s);
  TEST_ASSERT_EQUAL_INT(POUR_MODE_IDLE, ctl.mode);
}

static void test_params_apply_KeepsTheOldConfigWhenTheCoreRefuses(void) {
  const int32_t theta_max = ctl.config.safety.theta_max_urad;
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_theta_min, theta_max));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  TEST_ASSERT_EQUAL_INT32(pour_control_default_config().safety.theta_min_urad, ctl.config.safety.theta_min_urad);
  pour_control_step(&ctl, &in, &out); /* the core still runs on its old configuration */
  TEST_ASSERT_EQUAL_INT(POUR_MODE_IDLE, out.mode);
}

static void test_params_apply_InFaultKeepsTheFaultLatched(void) {
  in.estop = true;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_FALSE(pour_params_writable(&ctl)); /* ESTOP */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  in.estop = false;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_INT(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_TRUE(pour_params_writable(&ctl));
  TEST_ASSERT_EQUAL_INT(POUR_PARAM_OK, pour_params_set(&params, POUR_PARAM_ID_stop_timeout, 3000));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_INT(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_ESTOP, out.faults & POUR_FAULT_ESTOP);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_EQUAL_UINT16(3000u, ctl.config.stop.timeout_ms);
}

static void test_params_apply_RefusedInRun(void) {
  in.sensors_fresh = true;
  in.sensors.seq = 1;
  in.sensors.scale_rotating_g = 10000;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_INT(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_FALSE(pour_params_writable(&ctl));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  TEST_ASSERT_EQUAL_INT(POUR_MODE_RUN, ctl.mode);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_params_table_IsDenseAndEveryDefaultIsInRange);
  RUN_TEST(test_params_get_ReadsTheFieldsTheyLiveIn);
  RUN_TEST(test_params_set_RefusesOutOfRangeAndUnknownIds);
  RUN_TEST(test_params_set_RefusesAnEnvelopeBeyondTheSafetyCase);
  RUN_TEST(test_params_check_RefusesAZeroPastTheEncodersRange);
  RUN_TEST(test_params_correct_AppliesZeroTareAndFactor);
  RUN_TEST(test_params_blob_RoundTrips);
  RUN_TEST(test_params_blob_RefusesCorruptTruncatedAndForeignBlobs);
  RUN_TEST(test_params_blob_NamesAValueOutOfRange);
  RUN_TEST(test_params_apply_InIdleChangesTheCore);
  RUN_TEST(test_params_apply_KeepsTheOldConfigWhenTheCoreRefuses);
  RUN_TEST(test_params_apply_InFaultKeepsTheFaultLatched);
  RUN_TEST(test_params_apply_RefusedInRun);
  return UNITY_END();
}
