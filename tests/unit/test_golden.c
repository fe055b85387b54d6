/* SPDX-License-Identifier: MIT */
/* The C core against tests/golden/golden_vectors.h (python -m pour.policy.golden). The fixed-point
 * kernels (quantisation, logits, probabilities, greedy and sampled actions) against the independent Python
 * reference of them (pour.policy.fixedpoint), bit for bit. The stateful parts (the safety envelope with the
 * motion limits, the sensor estimator, whole control-step trajectories from raw sensor samples: modes,
 * faults, decision schedule) against what the C core itself did when the vectors were recorded (through
 * pour.core): regression pins, on the host and the emulated Cortex-M4 alike;
 * tests/python/test_core_properties.py checks them against docs/safety.md. */
#include <string.h>

#include "golden_vectors.h"
#include "pour/control.h"
#include "pour/obs.h"
#include "pour/policy.h"
#include "pour/safety.h"
#include "pour/sensors.h"
#include "pour/weights_compiled.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_golden_VectorsWereMadeFromTheCompiledExample(void) {
  TEST_ASSERT_EQUAL_HEX32(POUR_GOLDEN_EXAMPLE_HASH, pour_weights_compiled.content_hash);
  TEST_ASSERT_EQUAL_UINT8(POUR_GOLDEN_EXAMPLE_N_ACTIONS, pour_weights_compiled.n_actions);
}

static void test_golden_QuantizeMatchesThePythonKernelBitForBit(void) {
  for (unsigned i = 0; i < POUR_GOLDEN_N_QUANT; ++i) {
    const pour_golden_quant_t *g = &pour_golden_quant[i];
    const pour_obs_norm_t norm = {g->norm[0], g->norm[1], g->norm[2]};
    const pour_state_t s = {0u, g->state[0], g->state[1], (q15_t)g->state[2], (q15_t)g->state[3], (q15_t)g->state[4]};
    pour_obs_t obs;
    pour_obs_quantize(&norm, &s, &obs);
    TEST_ASSERT_EQUAL_INT16_ARRAY_MESSAGE(g->obs, obs.x, POUR_OBS_N, "quantisation case differs");
  }
}

static void test_golden_SoftmaxAndArgmaxMatchThePythonKernelsBitForBit(void) {
  for (unsigned i = 0; i < POUR_GOLDEN_N_SOFTMAX; ++i) {
    const pour_golden_softmax_t *g = &pour_golden_softmax[i];
    q15_t probs[POUR_POLICY_MAX_ACTIONS];
    pour_policy_softmax_q15(g->logits, g->n, probs);
    TEST_ASSERT_EQUAL_INT16_ARRAY_MESSAGE(g->probs, probs, g->n, "softmax case differs");
    TEST_ASSERT_EQUAL_UINT(g->argmax, pour_policy_argmax(g->logits, g->n));
  }
}

static void test_golden_GreedyPolicyLogitsProbsAndActionMatchThePythonKernelsBitForBit(void) {
  pour_policy_t policy;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  for (unsigned i = 0; i < POUR_GOLDEN_N_POLICY; ++i) {
    const pour_golden_policy_t *g = &pour_golden_policy[i];
    pour_obs_t obs;
    for (unsigned k = 0; k < POUR_OBS_N; ++k) {
      obs.x[k] = g->obs[k];
    }
    pour_policy_eval_t ev;
    pour_policy_eval(&policy, &obs, &ev);
    TEST_ASSERT_EQUAL_INT32_ARRAY(g->logits, ev.logits, POUR_GOLDEN_EXAMPLE_N_ACTIONS);
    TEST_ASSERT_EQUAL_INT16_ARRAY(g->probs, ev.probs, POUR_GOLDEN_EXAMPLE_N_ACTIONS);
    TEST_ASSERT_EQUAL_UINT8(g->action, ev.action);
  }
}

static void test_golden_SampledPolicyDrawsThePythonKernelsActions(void) {
  for (unsigned i = 0; i < POUR_GOLDEN_N_SAMPLED; ++i) {
    const pour_golden_sampled_t *g = &pour_golden_sampled[i];
    pour_policy_t policy;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_SAMPLED, g->seed));
    pour_obs_t obs;
    for (unsigned k = 0; k < POUR_OBS_N; ++k) {
      obs.x[k] = g->obs[k];
    }
    for (unsigned t = 0; t < POUR_GOLDEN_SAMPLED_LEN; ++t) {
      pour_policy_eval_t ev;
      pour_policy_eval(&policy, &obs, &ev);
      TEST_ASSERT_EQUAL_UINT8(g->actions[t], ev.action);
    }
  }
}

static void test_golden_SafetyEnvelopeRepeatsItsRecordedCommandsAndLimits(void) {
  for (unsigned i = 0; i < POUR_GOLDEN_N_SAFETY; ++i) {
    const pour_golden_safety_t *g = &pour_golden_safety[i];
    pour_safety_config_t config = pour_safety_default_config(); /* the vectors' configs have no fill schedule */
    config.tau_limit = (q15_t)g->config[0];
    config.slew_per_tick = (q15_t)g->config[1];
    config.theta_min_urad = g->config[2];
    config.theta_max_urad = g->config[3];
    config.omega_max_urad_s = g->config[4];
    config.alpha_max_urad_s2 = g->config[5];
    config.omega_slack_urad_s = g->config[6];
    config.governor_gain = (q15_t)g->config[7];
    pour_safety_t safety;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
    for (unsigned t = 0; t < POUR_GOLDEN_SAFETY_LEN; ++t) {
      const q15_t torque = pour_safety_apply(&safety, (q15_t)g->requested[t], g->theta[t], g->omega[t]);
      TEST_ASSERT_EQUAL_INT16(g->torque[t], torque);
      TEST_ASSERT_EQUAL_UINT8(g->active[t], safety.active);
    }
  }
}

static void test_golden_EstimatorRepeatsItsRecordedStates(void) {
  for (unsigned i = 0; i < POUR_GOLDEN_N_ESTIMATOR; ++i) {
    const pour_golden_estimator_t *g = &pour_golden_estimator[i];
    const pour_sensors_config_t config = {(uint8_t)g->config[0], (uint16_t)g->config[1], g->config[2], g->config[3],
                                          g->config[4], g->config[5]};
    static pour_estimator_t est;
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_estimator_init(&est, &config));
    pour_state_t state = {0u, 0, 0, 0, 0, 0};
    for (unsigned t = 0; t < POUR_GOLDEN_ESTIMATOR_LEN; ++t) {
      const pour_sensors_t sample = {g->sample[t][0], g->sample[t][1], (int32_t)g->sample[t][2],
                                     (int32_t)g->sample[t][3]};
      TEST_ASSERT_EQUAL_UINT8(g->ok[t], pour_estimator_update(&est, &sample, &state) ? 1u : 0u);
      const int32_t got[5] = {state.theta_urad, state.omega_urad_s, state.v_rotating, state.v_target, state.v_spill};
      TEST_ASSERT_EQUAL_INT32_ARRAY_MESSAGE(g->state[t], got, 5, "estimator sample differs");
    }
  }
}

static void replay_control(const int32_t *cfg, const pour_golden_tick_t *ticks) {
  pour_control_config_t config = pour_control_default_config();
  config.safety.tau_limit = (q15_t)cfg[0];
  config.safety.slew_per_tick = (q15_t)cfg[1];
  config.safety.theta_min_urad = cfg[2];
  config.safety.theta_max_urad = cfg[3];
  config.input_timeout_ms = (uint16_t)cfg[4];
  config.safe_torque = (q15_t)cfg[5];
  config.policy_mode = cfg[6] != 0 ? POUR_POLICY_SAMPLED : POUR_POLICY_GREEDY;
  config.seed = (uint32_t)cfg[7];
  config.safety.omega_max_urad_s = cfg[8];
  config.safety.alpha_max_urad_s2 = cfg[9];
  config.safety.omega_slack_urad_s = cfg[10];
  config.safety.governor_gain = (q15_t)cfg[11];
  config.sensors.encoder_bits = (uint8_t)cfg[12];
  config.sensors.bandwidth_rad_s = (uint16_t)cfg[13];
  /* The vectors pin the envelope's state machine on scripted, not physical, states; the supervisor that
   * judges physics has its own tests (test_supervisor.c) and stays out of them. */
  config.supervisor.checks = 0u;
  static pour_control_t ctl;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  for (unsigned t = 0; t < POUR_GOLDEN_CONTROL_LEN; ++t) {
    const pour_golden_tick_t *g = &ticks[t];
    pour_control_input_t in;
    memset(&in, 0, sizeof in); /* the inputs the vectors do not drive (link fault, stop, reset) stay off */
    in.sensors_fresh = (g->flags & 1u) != 0u;
    in.estop = (g->flags & 2u) != 0u;
    in.clear_faults = (g->flags & 4u) != 0u;
    in.sensors.seq = g->sample[0];
    in.sensors.encoder = g->sample[1];
    in.sensors.scale_rotating_g = (int32_t)g->sample[2];
    in.sensors.scale_target_g = (int32_t)g->sample[3];
    pour_control_output_t out;
    pour_control_step(&ctl, &in, &out);
    TEST_ASSERT_EQUAL_INT16(g->torque, out.torque);
    TEST_ASSERT_EQUAL_UINT8(g->action, out.action);
    TEST_ASSERT_EQUAL_UINT8(g->mode, out.mode);
    TEST_ASSERT_EQUAL_HEX16(g->faults, out.faults);
    TEST_ASSERT_EQUAL_HEX8(g->limits, out.limits);
    TEST_ASSERT_EQUAL_UINT32(t + 1u, out.tick);
  }
}

static void test_golden_ControlStepGreedyRepeatsItsRecordedTrajectory(void) {
  replay_control(pour_golden_control_config_0, pour_golden_control_0);
}

static void test_golden_ControlStepSampledRepeatsItsRecordedTrajectory(void) {
  replay_control(pour_golden_control_config_1, pour_golden_control_1);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_golden_VectorsWereMadeFromTheCompiledExample);
  RUN_TEST(test_golden_QuantizeMatchesThePythonKernelBitForBit);
  RUN_TEST(test_golden_SoftmaxAndArgmaxMatchThePythonKernelsBitForBit);
  RUN_TEST(test_golden_GreedyPolicyLogitsProbsAndActionMatchThePythonKernelsBitForBit);
  RUN_TEST(test_golden_SampledPolicyDrawsThePythonKernelsActions);
  RUN_TEST(test_golden_SafetyEnvelopeRepeatsItsRecordedCommandsAndLimits);
  RUN_TEST(test_golden_EstimatorRepeatsItsRecordedStates);
  RUN_TEST(test_golden_ControlStepGreedyRepeatsItsRecordedTrajectory);
  RUN_TEST(test_golden_ControlStepSampledRepeatsItsRecordedTrajectory);
  return UNITY_END();
}
