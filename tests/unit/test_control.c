/* SPDX-License-Identifier: MIT */
#include "pour/control.h"
#include "pour/weights_compiled.h"
#include "unity.h"

static pour_control_config_t config;
static pour_control_t ctl;
static pour_control_input_t in;
static pour_control_output_t out;

/* Upright, still, full rotating bucket: the example policy pushes forward. */
static pour_state_t start_state(void) {
  pour_state_t s = {0u, 0, 0, 32767, 0, 0};
  return s;
}

static void step(bool fresh) {
  in.state_fresh = fresh;
  if (fresh) {
    in.state.seq++;
  }
  pour_control_step(&ctl, &in, &out);
}

void setUp(void) {
  config = pour_control_default_config();
  /* The states here are scripted, not physical (a bucket that never moves under torque, volumes that jump):
   * the supervisor's motion and volume checks would rightly object. test_supervisor.c covers them. */
  config.supervisor.checks = POUR_CHECK_POSITION | POUR_CHECK_OVERSPEED | POUR_CHECK_SEQ;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  in.state_fresh = false;
  in.state = start_state();
  in.estop = false;
  in.clear_faults = false;
}

void tearDown(void) {}

static void test_control_init_RefusesBadConfig(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(NULL, &config, &pour_weights_compiled));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, NULL, &pour_weights_compiled));
  config.input_timeout_ms = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.safety.tau_limit = 1000;
  config.safe_torque = 2000;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.safety.slew_per_tick = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.plausible_volume_sum = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
}

static void test_control_init_PassesOnAWeightsError(void) {
  pour_policy_weights_t bad = pour_weights_compiled;
  bad.content_hash ^= 0x10u;
  TEST_ASSERT_EQUAL_INT(POUR_ECORRUPT, pour_control_init(&ctl, &config, &bad));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, NULL));
}

static void test_control_step_IdleWaitsForFirstStateWithoutTimingOut(void) {
  for (unsigned i = 0; i < 1000u; ++i) {
    step(false);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    TEST_ASSERT_EQUAL_INT16(0, out.torque);
  }
  TEST_ASSERT_EQUAL_UINT16(0u, out.faults);
  TEST_ASSERT_EQUAL_UINT32(1000u, out.tick);
}

static void test_control_step_FirstFreshStateStartsRunAndDecides(void) {
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_TRUE(pour_weights_compiled.action_levels[out.action] > 0);
  TEST_ASSERT_EQUAL_INT16(config.safety.slew_per_tick, out.torque); /* slewing up from zero */
  step(true); /* a greedy decision's probabilities come with the tick after it */
  int32_t sum = 0;
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    sum += out.probs[a];
  }
  TEST_ASSERT_INT_WITHIN(6, 32768, sum);
}

static void test_control_step_GreedyProbabilitiesFollowTheDecisionByOneTick(void) {
  step(true);
  const uint8_t action = out.action;
  int32_t sum = 0;
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    sum += out.probs[a];
  }
  TEST_ASSERT_EQUAL_INT32(0, sum); /* the decision tick carries only the action: it is the costly one */
  step(true);
  pour_policy_eval_t ev;
  pour_policy_t policy;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  pour_policy_eval(&policy, &ctl.obs, &ev);
  TEST_ASSERT_EQUAL_UINT8(action, ev.action);
  TEST_ASSERT_EQUAL_INT16_ARRAY(ev.probs, out.probs, POUR_POLICY_MAX_ACTIONS);
}

static void test_control_step_DecidesEveryPeriodAndHoldsBetween(void) {
  const unsigned period = pour_weights_compiled.decision_period_ms;
  step(true);
  const uint8_t first = out.action;
  /* From now on the state says "poured, tilted": the policy wants to pull back, but only the next
   * decision tick may change the action. */
  in.state.theta_urad = 2000000;
  in.state.v_rotating = 500;
  in.state.v_target = 32000;
  for (unsigned k = 1; k < period; ++k) {
    step(true);
    TEST_ASSERT_EQUAL_UINT8(first, out.action);
  }
  step(true); /* tick period + 1: the second decision */
  TEST_ASSERT_NOT_EQUAL(first, out.action);
  TEST_ASSERT_TRUE(pour_weights_compiled.action_levels[out.action] < 0);
}

static void test_control_step_StaleInputAfterTimeoutGivesSafeTorqueAndLatches(void) {
  for (unsigned i = 0; i < 30u; ++i) {
    step(true);
  }
  TEST_ASSERT_TRUE(out.torque > 0);
  for (unsigned i = 0; i < config.input_timeout_ms; ++i) {
    step(false);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  }
  step(false);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_STALE_INPUT, out.faults);
  TEST_ASSERT_EQUAL_INT16(config.safe_torque, out.torque); /* at once, not slewed */
  for (unsigned i = 0; i < 50u; ++i) {
    step(true); /* fresh states do not clear a latched fault */
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
    TEST_ASSERT_EQUAL_INT16(config.safe_torque, out.torque);
  }
}

static void test_control_step_ClearReturnsToIdleThenRun(void) {
  step(true);
  for (unsigned i = 0; i <= config.input_timeout_ms; ++i) {
    step(false);
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  in.clear_faults = true;
  step(false);
  in.clear_faults = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_UINT16(0u, out.faults);
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

static void test_control_step_EstopZeroesTorqueInTheSameTick(void) {
  for (unsigned i = 0; i < 40u; ++i) {
    step(true);
  }
  TEST_ASSERT_TRUE(out.torque > 10000);
  in.estop = true;
  step(true);
  TEST_ASSERT_EQUAL_INT16(0, out.torque);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_ESTOP, out.faults);
  in.clear_faults = true; /* ignored while the e-stop is held */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  in.clear_faults = false;
  in.estop = false;
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode); /* released: latched until cleared */
  TEST_ASSERT_EQUAL_INT16(0, out.torque);
  in.clear_faults = true;
  step(true);
  in.clear_faults = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode); /* cleared, and this tick's fresh state restarts */
  TEST_ASSERT_EQUAL_INT16(config.safety.slew_per_tick, out.torque);
}

static void expect_bad_input(pour_state_t s) {
  setUp();
  step(true);
  in.state = s;
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_BAD_INPUT, out.faults);
  TEST_ASSERT_EQUAL_INT16(config.safe_torque, out.torque);
}

static void test_control_step_ImpossibleStatesRaiseBadInput(void) {
  pour_state_t s = start_state();
  s.v_rotating = -1;
  expect_bad_input(s);
  s = start_state();
  s.v_spill = INT16_MIN;
  expect_bad_input(s);
  s = start_state();
  s.v_target = 32767; /* with v_rotating = 32767: twice the liquid there is */
  expect_bad_input(s);
  s = start_state();
  s.theta_urad = INT32_MIN;
  expect_bad_input(s);
  s = start_state();
  s.theta_urad = 4000000; /* past half a turn */
  expect_bad_input(s);
  s = start_state();
  s.omega_urad_s = INT32_MAX;
  expect_bad_input(s);
}

static void test_control_step_BadInputInIdleAlsoFaults(void) {
  in.state.v_rotating = -5;
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_BAD_INPUT, out.faults);
}

static void test_control_step_NoForwardTorquePastMaxAngle(void) {
  for (unsigned i = 0; i < 40u; ++i) {
    step(true);
  }
  TEST_ASSERT_TRUE(out.torque > 0);
  in.state.theta_urad = config.safety.theta_max_urad + 1000;
  in.state.v_rotating = 32767; /* the policy still wants to push */
  for (unsigned i = 0; i < 25u; ++i) {
    step(true);
    TEST_ASSERT_TRUE(out.torque <= 0);
  }
}

static void test_control_step_IsDeterministic(void) {
  pour_control_t other;
  pour_control_output_t out2;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&other, &config, &pour_weights_compiled));
  for (unsigned i = 0; i < 500u; ++i) {
    in.state.theta_urad = (int32_t)(i * 3000u);
    in.state.v_rotating = (q15_t)(32767 - (int32_t)i * 60);
    in.state.v_target = (q15_t)(i * 60u);
    step(true);
    pour_control_step(&other, &in, &out2);
    TEST_ASSERT_EQUAL_INT16(out.torque, out2.torque);
    TEST_ASSERT_EQUAL_UINT8(out.action, out2.action);
  }
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_control_init_RefusesBadConfig);
  RUN_TEST(test_control_init_PassesOnAWeightsError);
  RUN_TEST(test_control_step_IdleWaitsForFirstStateWithoutTimingOut);
  RUN_TEST(test_control_step_FirstFreshStateStartsRunAndDecides);
  RUN_TEST(test_control_step_GreedyProbabilitiesFollowTheDecisionByOneTick);
  RUN_TEST(test_control_step_DecidesEveryPeriodAndHoldsBetween);
  RUN_TEST(test_control_step_StaleInputAfterTimeoutGivesSafeTorqueAndLatches);
  RUN_TEST(test_control_step_ClearReturnsToIdleThenRun);
  RUN_TEST(test_control_step_EstopZeroesTorqueInTheSameTick);
  RUN_TEST(test_control_step_ImpossibleStatesRaiseBadInput);
  RUN_TEST(test_control_step_BadInputInIdleAlsoFaults);
  RUN_TEST(test_control_step_NoForwardTorquePastMaxAngle);
  RUN_TEST(test_control_step_IsDeterministic);
  return UNITY_END();
}
