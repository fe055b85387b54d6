/* SPDX-License-Identifier: MIT */
/* poursim_rollout: the arrays it fills, the decision schedule, the safety envelope, determinism. */
#include <math.h>
#include <string.h>

#include "pour/control.h"
#include "poursim/poursim.h"
#include "unity.h"

#define N_ACT 5
#define MAX_DEC 2000
#define MAX_STEPS 3000

static poursim_config_t cfg;
static poursim_world_t *world;
static char err[POURSIM_ERR_LEN];
static double w[POURSIM_N_FEATURES * N_ACT];
static double levels[N_ACT] = {-1.0, -0.5, 0.0, 0.5, 1.0};
static poursim_policy_t pol;
static double features[MAX_DEC * POURSIM_N_FEATURES], rewards[MAX_DEC], probs[MAX_DEC * N_ACT];
static int32_t actions[MAX_DEC];
static double step_rewards[MAX_STEPS], step_theta[MAX_STEPS], step_torque[MAX_STEPS];

static poursim_rollout_buffers_t buffers(void) {
  poursim_rollout_buffers_t b = {MAX_DEC, features, actions, rewards, probs, MAX_STEPS, step_rewards, step_theta, step_torque};
  return b;
}

void setUp(void) {
  cfg = poursim_default_config();
  cfg.episode_s = 3.0; /* short episodes keep the test quick */
  world = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(world, err);
  /* Tilt while upright, hold back once liquid has left: uses θ, V_rot and the bias. */
  memset(w, 0, sizeof w);
  for (int a = 0; a < N_ACT; ++a) {
    w[0 * N_ACT + a] = -3.0 * levels[a]; /* θn */
    w[2 * N_ACT + a] = 2.0 * levels[a];  /* V_rot */
    w[5 * N_ACT + a] = 1.0 * levels[a];  /* bias */
  }
  memset(&pol, 0, sizeof pol);
  pol.n_actions = N_ACT;
  pol.decision_period = 10;
  pol.w = w;
  pol.levels = levels;
  pol.theta_min = 0.0;
  pol.theta_max = 2.356194;
  pol.omega_max = 4.0;
  pol.greedy = 1;
}

void tearDown(void) { poursim_destroy(world); }

static void test_rollout_FillsArraysConsistently(void) {
  poursim_rollout_buffers_t b = buffers();
  poursim_episode_t ep;
  pol.greedy = 0;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout(world, &pol, 5, &b, &ep));
  TEST_ASSERT_EQUAL_INT(3000, ep.n_steps);
  TEST_ASSERT_EQUAL_INT(300, ep.n_decisions);
  double sum = 0.0, step_sum = 0.0;
  for (int d = 0; d < ep.n_decisions; ++d) {
    sum += rewards[d];
    TEST_ASSERT_TRUE(actions[d] >= 0 && actions[d] < N_ACT);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, features[d * POURSIM_N_FEATURES + 5]);
    double p = 0.0;
    for (int k = 0; k < POURSIM_N_FEATURES; ++k) {
      double x = features[d * POURSIM_N_FEATURES + k];
      TEST_ASSERT_TRUE(x >= 0.0 && x <= 1.0);
    }
    for (int a = 0; a < N_ACT; ++a) p += probs[d * N_ACT + a];
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0, p);
  }
  double ret = 0.0, disc = 1.0;
  for (int t = 0; t < ep.n_steps; ++t) {
    step_sum += step_rewards[t];
    ret += disc * step_rewards[t];
    disc *= cfg.gamma;
  }
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, ep.reward_sum, sum);
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, ep.reward_sum, step_sum);
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, ret, ep.ret); /* R = Σ γ^t r_t */
  TEST_ASSERT_TRUE(ep.max_theta > 0.2); /* the policy did tilt the bucket */
}

/* The rollout must equal a hand-written loop around the firmware's pipeline: each step's sensor sample into
 * pour_control_update, the policy's decision (at steps 0, P, 2P of the run) from the state the core
 * estimated as a pour_control_request, pour_control_shape, the brake and the torque to the world. Compared
 * bit for bit through the torque and θ of every step. */
static void test_rollout_MatchesManualLoopThroughTheFirmwarePipeline(void) {
  poursim_rollout_buffers_t b = buffers();
  poursim_episode_t ep;
  pol.decision_period = 7;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout(world, &pol, 3, &b, &ep));
  TEST_ASSERT_EQUAL_INT(429, ep.n_decisions); /* ceil(3000 / 7) */

  poursim_reset(world, 3);
  pour_control_config_t fw = pour_control_default_config();
  fw.sensors.encoder_bits = (uint8_t)cfg.encoder_bits;
  pour_control_t ctl;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &fw, 7u));
  pour_control_input_t in;
  memset(&in, 0, sizeof in);
  pour_control_output_t out;
  poursim_obs_t o;
  poursim_observe(world, &o);
  int action = 0, limited = 0, decisions = 0;
  for (int t = 0; t < 3000; ++t) {
    const pour_sensors_t sample = {(uint32_t)t, o.encoder, o.scale_rotating_g, o.scale_target_g};
    in.sensors_fresh = true;
    in.sensors = sample;
    q15_t req = 0;
    if (pour_control_update(&ctl, &in)) {
      const pour_state_t *s = pour_control_state(&ctl);
      const double th = s->theta_urad * 1e-6, om = s->omega_urad_s * 1e-6;
      double x[6] = {fmin(fmax(th / 2.356194, 0), 1), fmin(fmax((om + 4.0) / 8.0, 0), 1), s->v_rotating / 32768.0,
                     s->v_target / 32768.0, s->v_spill / 32768.0, 1.0};
      for (int k = 2; k < 5; ++k) x[k] = fmin(fmax(x[k], 0), 1);
      double best = -INFINITY;
      for (int a = 0; a < N_ACT; ++a) {
        double l = 0.0;
        for (int k = 0; k < 6; ++k) l += x[k] * w[k * N_ACT + a];
        if (l > best) best = l, action = a;
      }
      TEST_ASSERT_EQUAL_INT(action, actions[decisions++]);
      const double q = nearbyint(levels[action] * 32768.0);
      req = (q15_t)(q > 32767.0 ? 32767.0 : q);
      pour_control_request(&ctl, (uint8_t)action, req);
    }
    pour_control_shape(&ctl, &out);
    limited |= out.limits != 0u;
    TEST_ASSERT_EQUAL_DOUBLE(out.torque / 32768.0, step_torque[t]);
    poursim_set_brake(world, out.brake ? 1 : 0);
    poursim_step(world, out.torque / 32768.0, &o);
    TEST_ASSERT_EQUAL_DOUBLE(o.theta, step_theta[t]);
  }
  TEST_ASSERT_EQUAL_INT(ep.n_decisions, decisions);
  TEST_ASSERT_EQUAL_INT(out.faults, ep.faults);
  TEST_ASSERT_TRUE(limited); /* the envelope did shape the command (slew limit at least) */
}

static void test_rollout_IsDeterministicAndBatchMatchesSequential(void) {
  poursim_episode_t a, b2;
  pol.greedy = 0;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout(world, &pol, 11, NULL, &a));
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout(world, &pol, 11, NULL, &b2));
  TEST_ASSERT_EQUAL_DOUBLE(a.ret, b2.ret);
  uint32_t seeds[3] = {11, 12, 13};
  poursim_episode_t batch[3], seq[3];
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout_batch(&cfg, &pol, seeds, 3, 2, NULL, batch, err, sizeof err));
  for (int i = 0; i < 3; ++i) {
    poursim_rollout(world, &pol, seeds[i], NULL, &seq[i]);
    TEST_ASSERT_EQUAL_DOUBLE(seq[i].ret, batch[i].ret);
    TEST_ASSERT_EQUAL_DOUBLE(seq[i].poured, batch[i].poured);
  }
  TEST_ASSERT_EQUAL_DOUBLE(a.ret, batch[0].ret);
}

/* The rollout ends where host_sim's episodes do: at the first observation that says done (12 steps for
 * 12.5 ms, where rounding episode_s / dt would give 13). */
static void test_rollout_EndsAtTheObservationThatSaysDone(void) {
  poursim_destroy(world);
  cfg.episode_s = 0.0125;
  world = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(world, err);
  poursim_episode_t ep;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout(world, &pol, 2, NULL, &ep));
  poursim_obs_t o;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_reset(world, 2));
  poursim_observe(world, &o);
  int steps = 0;
  while (!o.done) {
    TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_step(world, 0.0, &o));
    ++steps;
  }
  TEST_ASSERT_EQUAL_INT(12, steps);
  TEST_ASSERT_EQUAL_INT(steps, ep.n_steps);
  TEST_ASSERT_EQUAL_INT(2, ep.n_decisions); /* steps 0 and 10 */
}

static void test_rollout_RefusesBadPolicy(void) {
  poursim_episode_t ep;
  pol.n_actions = 1;
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_rollout(world, &pol, 1, NULL, &ep));
  pol.n_actions = N_ACT;
  w[3] = NAN;
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_rollout(world, &pol, 1, NULL, &ep));
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL,
                        poursim_rollout_batch(&cfg, &pol, (uint32_t[]){1}, 1, 1, NULL, &ep, err, sizeof err));
  TEST_ASSERT_NOT_NULL(strstr(err, "w[3]"));
  w[3] = 0.0;
  levels[0] = -1.5;
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_rollout(world, &pol, 1, NULL, &ep));
  levels[0] = -1.0;
  pol.decision_period = 0;
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_rollout(world, &pol, 1, NULL, &ep));
}

static void test_fraction_to_q15_RoundsHalfUpSaturatesAndMapsNanToZero(void) {
  const double lsb = 1.0 / 32768.0;
  TEST_ASSERT_EQUAL_INT16(0, poursim_fraction_to_q15(NAN));
  TEST_ASSERT_EQUAL_INT16(32767, poursim_fraction_to_q15(INFINITY));
  TEST_ASSERT_EQUAL_INT16(-32768, poursim_fraction_to_q15(-INFINITY));
  TEST_ASSERT_EQUAL_INT16(32767, poursim_fraction_to_q15(1.0));
  TEST_ASSERT_EQUAL_INT16(-32768, poursim_fraction_to_q15(-1.0));
  TEST_ASSERT_EQUAL_INT16(32767, poursim_fraction_to_q15(1e300));
  TEST_ASSERT_EQUAL_INT16(1, poursim_fraction_to_q15(0.5 * lsb)); /* half an LSB: up */
  TEST_ASSERT_EQUAL_INT16(0, poursim_fraction_to_q15(0.4999999 * lsb));
  TEST_ASSERT_EQUAL_INT16(3, poursim_fraction_to_q15(2.5 * lsb));
  TEST_ASSERT_EQUAL_INT16(0, poursim_fraction_to_q15(-0.5 * lsb)); /* up is toward +inf */
  TEST_ASSERT_EQUAL_INT16(-1, poursim_fraction_to_q15(-1.5 * lsb));
  TEST_ASSERT_EQUAL_INT16(32767, poursim_fraction_to_q15(32766.5 * lsb));
  TEST_ASSERT_EQUAL_INT16(-32768, poursim_fraction_to_q15(-32768.5 * lsb));
}

/* Training sees the core it will run on: full torque into the hard stop is more acceleration than the
 * command can give (the supervisor's SCALE check), the core faults, the decisions end, the controlled stop
 * takes over and the bucket ends held; the episode says so. */
static void test_rollout_ReportsTheCoresFaultAndItsStop(void) {
  poursim_rollout_buffers_t b = buffers();
  poursim_episode_t ep;
  memset(w, 0, sizeof w);
  for (int a = 0; a < N_ACT; ++a) w[5 * N_ACT + a] = 3.0 * levels[a]; /* always the top level */
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_rollout(world, &pol, 3, &b, &ep));
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_SCALE, ep.faults);
  TEST_ASSERT_TRUE(ep.fault_step > 0 && ep.fault_step < ep.n_steps);
  TEST_ASSERT_EQUAL_INT((ep.fault_step + 9) / 10, ep.n_decisions); /* no decision once it faulted */
  for (int t = ep.fault_step; t < ep.n_steps; ++t) {
    TEST_ASSERT_TRUE(step_torque[t] <= 0.5); /* the stop's torque bound, never the policy's +1 */
  }
  TEST_ASSERT_EQUAL_DOUBLE(0.0, step_torque[ep.n_steps - 1]); /* stopped: the safe torque, brake engaged */
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_rollout_FillsArraysConsistently);
  RUN_TEST(test_rollout_MatchesManualLoopThroughTheFirmwarePipeline);
  RUN_TEST(test_rollout_ReportsTheCoresFaultAndItsStop);
  RUN_TEST(test_rollout_IsDeterministicAndBatchMatchesSequential);
  RUN_TEST(test_rollout_EndsAtTheObservationThatSaysDone);
  RUN_TEST(test_rollout_RefusesBadPolicy);
  RUN_TEST(test_fraction_to_q15_RoundsHalfUpSaturatesAndMapsNanToZero);
  return UNITY_END();
}
