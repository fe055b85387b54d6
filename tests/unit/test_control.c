/* SPDX-License-Identifier: MIT */
#include <string.h>

#include "pour/control.h"
#include "pour/weights_compiled.h"
#include "unity.h"

static pour_control_config_t config;
static pour_control_t ctl;
static pour_control_input_t in;
static pour_control_output_t out;

#define FULL_G 10000 /* 10 kg of liquid, all in the rotating bucket */

/* The raw count of the default 17-bit encoder at θ [µrad] (0 = upright, below upright wraps). */
static uint32_t count_at(int32_t theta_urad) {
  const int64_t c = ((int64_t)theta_urad * 131072 * 1000 + (theta_urad >= 0 ? 3141592654LL : -3141592654LL)) /
                    6283185307LL;
  return (uint32_t)((c + 131072) % 131072);
}

/* What the sensors read: θ [µrad] and the two scales [g]. */
static void sense(int32_t theta_urad, int32_t m_rot_g, int32_t m_tgt_g) {
  in.sensors.encoder = count_at(theta_urad);
  in.sensors.scale_rotating_g = m_rot_g;
  in.sensors.scale_target_g = m_tgt_g;
}

static void step(bool fresh) {
  in.sensors_fresh = fresh;
  if (fresh) {
    in.sensors.seq++;
  }
  pour_control_step(&ctl, &in, &out);
}

void setUp(void) {
  config = pour_control_default_config();
  /* The states here are scripted, not physical (a bucket that never moves under torque, volumes that jump):
   * the supervisor's motion and volume checks would rightly object. test_supervisor.c covers them. */
  config.supervisor.checks = POUR_CHECK_POSITION | POUR_CHECK_OVERSPEED | POUR_CHECK_SEQ;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  in.sensors_fresh = false;
  in.sensors.seq = 0u;
  sense(0, FULL_G, 0); /* upright, still, the liquid in the rotating bucket: the example policy pushes */
  in.estop = false;
  in.clear_faults = false;
  in.stop = false;
  in.reset = false;
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
  config = pour_control_default_config();
  config.sensors.encoder_bits = 30u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.safety.omega_max_urad_s = 0;
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

static void test_control_step_FirstFreshSampleStartsRunAndDecides(void) {
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_TRUE(pour_weights_compiled.action_levels[out.action] > 0);
  TEST_ASSERT_EQUAL_INT16(config.safety.slew_per_tick, out.torque); /* slewing up from zero */
  pour_control_probs(&ctl, &out); /* a greedy decision's probabilities, when asked for */
  int32_t sum = 0;
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    sum += out.probs[a];
  }
  TEST_ASSERT_INT_WITHIN(6, 32768, sum);
}

static void test_control_step_GreedyProbabilitiesOnlyWhenAskedFor(void) {
  memset(out.probs, 0x5A, sizeof out.probs);
  step(true);
  const uint8_t action = out.action;
  for (unsigned a = 0; a < POUR_POLICY_MAX_ACTIONS; ++a) {
    TEST_ASSERT_EQUAL_HEX16(0x5A5A, (uint16_t)out.probs[a]); /* the step computes no softmax and leaves them */
  }
  TEST_ASSERT_TRUE(ctl.probs_pending);
  for (unsigned i = 0; i < 3u; ++i) {
    step(true); /* nor does any tick after it */
  }
  TEST_ASSERT_TRUE(ctl.probs_pending);
  pour_control_probs(&ctl, &out);
  TEST_ASSERT_FALSE(ctl.probs_pending);
  pour_policy_eval_t ev;
  pour_policy_t policy;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_init(&policy, &pour_weights_compiled, POUR_POLICY_GREEDY, 1u));
  pour_policy_eval(&policy, &ctl.obs, &ev);
  TEST_ASSERT_EQUAL_UINT8(action, ev.action);
  TEST_ASSERT_EQUAL_INT16_ARRAY(ev.probs, out.probs, POUR_POLICY_MAX_ACTIONS);
  q15_t again[POUR_POLICY_MAX_ACTIONS];
  memcpy(again, out.probs, sizeof again);
  memset(out.probs, 0, sizeof out.probs);
  pour_control_probs(&ctl, &out); /* asked again: the same, without a second softmax */
  TEST_ASSERT_EQUAL_INT16_ARRAY(again, out.probs, POUR_POLICY_MAX_ACTIONS);
}

static void test_control_step_DecidesEveryPeriodAndHoldsBetween(void) {
  const unsigned period = pour_weights_compiled.decision_period_ms;
  sense(2000000, FULL_G, 0); /* tilted, still full: the policy pushes on */
  step(true);
  const uint8_t first = out.action;
  TEST_ASSERT_TRUE(pour_weights_compiled.action_levels[first] > 0);
  /* From now on the scales say "poured": the policy wants to pull back, but only the next decision tick
   * may change the action. */
  sense(2000000, 150, 9800);
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

/* A run, then one sample that cannot be (encoder, scales as given), then plausible samples again: the
 * fault latches, the torque is the safe one at once, and the bad sample is never used. */
static void expect_bad_input(uint32_t encoder, int32_t m_rot_g, int32_t m_tgt_g) {
  setUp();
  for (unsigned i = 0; i < 30u; ++i) {
    step(true);
  }
  const pour_state_t good = ctl.state;
  in.sensors.encoder = encoder;
  in.sensors.scale_rotating_g = m_rot_g;
  in.sensors.scale_target_g = m_tgt_g;
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_BAD_INPUT, out.faults);
  TEST_ASSERT_EQUAL_INT16(config.safe_torque, out.torque);
  TEST_ASSERT_EQUAL_INT32(good.theta_urad, ctl.state.theta_urad);
  TEST_ASSERT_EQUAL_INT16(good.v_rotating, ctl.state.v_rotating);
  sense(0, FULL_G, 0);
  for (unsigned i = 0; i < 20u; ++i) {
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  }
}

static void test_control_step_ImplausibleSamplesRaiseBadInput(void) {
  expect_bad_input(131072u, FULL_G, 0);                     /* a count a 17-bit encoder cannot give */
  expect_bad_input(UINT32_MAX, FULL_G, 0);
  expect_bad_input(0u, config.sensors.scale_max_g + 1, 0);  /* a scale beyond its range */
  expect_bad_input(0u, FULL_G, config.sensors.scale_min_g - 1);
  expect_bad_input(0u, INT32_MIN, INT32_MAX);
  expect_bad_input(count_at(3000000), FULL_G, 0);           /* half a turn in 1 ms: a count that jumped */
  expect_bad_input(count_at(20000), FULL_G, 0);             /* 20 mrad in 1 ms: 40,000 rad/s² */
}

/* The volume-sum check, off by default (load cells read more than the liquid under impact and slosh), still
 * refuses what it is set to. */
static void test_control_step_VolumeSumCheckRefusesWhenArmed(void) {
  config.plausible_volume_sum = 40000; /* 1.22 */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  step(true);
  sense(0, FULL_G, FULL_G / 2);
  step(true);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_BAD_INPUT, out.faults);
  setUp();
  step(true);
  sense(0, FULL_G, FULL_G); /* twice the liquid: each cell clipped at 1, the sum at 2: passes by default */
  step(true);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
}

static void test_control_step_BadInputInIdleAlsoFaults(void) {
  sense(0, 300, 200); /* m0 = 0.5 kg: no liquid to measure a pour by */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_BAD_INPUT, out.faults);
}

/* Each run's estimate starts from the run's first sample: m0 is the liquid as it is then, θ̇ from rest. */
static void test_control_step_EachRunStartsTheEstimateAfresh(void) {
  sense(0, 8000, 0);
  step(true);
  TEST_ASSERT_EQUAL_INT16(32767, ctl.state.v_rotating);
  in.stop = true;
  step(false);
  in.stop = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  in.reset = true; /* the next run: the host's Stop + Reset (docs/can.md) */
  step(false);
  in.reset = false;
  sense(0, 4000, 0); /* half of it was poured out by hand */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_INT16(32767, ctl.state.v_rotating);
  TEST_ASSERT_EQUAL_INT32(4000, ctl.estimator.m0_g);
}

/* A Stop ends the run held: samples keep coming (a rig's sensor node streams all the time) and none starts a
 * new run, the brake engaged and the power off, until a Reset arms one (the virtual board's finding). */
static void test_control_stop_HoldsTheAxisWhileSamplesKeepComing(void) {
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  in.stop = true;
  step(true);
  in.stop = false;
  for (int i = 0; i < 2000; ++i) {
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    TEST_ASSERT_TRUE(out.brake);
    TEST_ASSERT_FALSE(out.power);
    TEST_ASSERT_TRUE(pour_control_held(&ctl));
  }
  TEST_ASSERT_EQUAL_INT16(config.safe_torque, out.torque);
  TEST_ASSERT_EQUAL_UINT32(0u, out.refused);
  in.reset = true; /* the Reset arms the next run: it starts on the next fresh sample */
  step(false);
  in.reset = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_FALSE(pour_control_held(&ctl));
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_FALSE(out.brake);
}

/* A port's boot (pour_control_hold after init): no run starts on the stream until a Reset; a clear of a fault
 * meanwhile does not arm one either. */
static void test_control_hold_AtBootNoRunUntilAReset(void) {
  pour_control_hold(&ctl);
  for (int i = 0; i < 100; ++i) {
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    TEST_ASSERT_TRUE(out.brake);
  }
  in.estop = true; /* an e-stop and its clear in between: still held */
  step(true);
  in.estop = false;
  step(true);
  in.clear_faults = true;
  step(true);
  in.clear_faults = false;
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
  for (int i = 0; i < 100; ++i) {
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  }
  TEST_ASSERT_TRUE(pour_control_held(&ctl));
  in.reset = true;
  step(true); /* a Reset and a sample in one tick: the run starts in it */
  in.reset = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  pour_control_hold(&ctl); /* in RUN it does nothing: a Stop ends a run */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_FALSE(pour_control_held(&ctl));
}

/* Moving forward slowly (0.3 rad/s) past θ_max: forward torque before it, none from the first sample past it. */
static void test_control_step_NoForwardTorquePastMaxAngle(void) {
  const int32_t start = config.safety.theta_max_urad - 6000;
  bool pushed = false;
  for (int32_t i = 0; i < 45; ++i) {
    sense(start + 300 * i, FULL_G, 0); /* the policy wants to push all the way */
    step(true);
    if (ctl.state.theta_urad >= config.safety.theta_max_urad) {
      TEST_ASSERT_TRUE(out.torque <= 0);
    } else {
      pushed = pushed || out.torque > 0;
    }
  }
  TEST_ASSERT_TRUE(pushed);
}

static void test_control_step_IsDeterministic(void) {
  pour_control_t other;
  pour_control_output_t out2;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&other, &config, &pour_weights_compiled));
  for (int32_t i = 0; i < 500; ++i) {
    sense(i * 3000, FULL_G - i * 18, i * 18);
    step(true);
    pour_control_step(&other, &in, &out2);
    TEST_ASSERT_EQUAL_INT16(out.torque, out2.torque);
    TEST_ASSERT_EQUAL_UINT8(out.action, out2.action);
  }
}

/* An outside decision that asks for what the policy chose gives the policy's run, tick for tick: the
 * stages are one implementation whichever decides. */
static void test_control_request_OfThePolicysLevelsRepeatsItsRun(void) {
  pour_control_t ext;
  TEST_ASSERT_EQUAL_INT(POUR_OK,
                        pour_control_init_external(&ext, &config, pour_weights_compiled.decision_period_ms));
  for (unsigned t = 0; t < 300u; ++t) {
    sense((int32_t)(t * 2000u), FULL_G - (int32_t)(t * 10u), (int32_t)(t * 9u));
    step(true);
    pour_control_output_t got;
    if (pour_control_update(&ext, &in)) {
      pour_control_request(&ext, out.action, pour_weights_compiled.action_levels[out.action]);
    }
    pour_control_shape(&ext, &got);
    TEST_ASSERT_EQUAL_INT16(out.torque, got.torque);
    TEST_ASSERT_EQUAL_UINT8(out.action, got.action);
    TEST_ASSERT_EQUAL_UINT8(out.mode, got.mode);
    TEST_ASSERT_EQUAL_UINT16(out.faults, got.faults);
    TEST_ASSERT_EQUAL_UINT8(out.limits, got.limits);
    TEST_ASSERT_EQUAL_INT32(pour_control_state(&ctl)->theta_urad, pour_control_state(&ext)->theta_urad);
  }
}

/* A request from outside passes the same envelope (slew, clamp) and, after a fault, the same stop. */
static void test_control_request_GoesThroughTheEnvelopeAndTheStop(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init_external(&ctl, &config, 0u));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init_external(NULL, &config, 1u));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &config, 5u));
  unsigned due = 0u;
  for (unsigned t = 0; t < 20u; ++t) {
    in.sensors_fresh = true;
    in.sensors.seq++;
    if (pour_control_update(&ctl, &in)) {
      due++;
      pour_control_request(&ctl, 3u, POUR_Q15_MAX);
    }
    pour_control_shape(&ctl, &out);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
    TEST_ASSERT_TRUE(out.torque <= config.safety.tau_limit);
    TEST_ASSERT_TRUE((int32_t)out.torque <= (int32_t)(t + 1u) * config.safety.slew_per_tick);
    TEST_ASSERT_EQUAL_UINT8(3u, out.action);
  }
  TEST_ASSERT_EQUAL_UINT(4u, due); /* ticks 0, 5, 10, 15 of the run */
  in.estop = true;
  TEST_ASSERT_FALSE(pour_control_update(&ctl, &in));
  pour_control_request(&ctl, 3u, POUR_Q15_MAX); /* ignored: ESTOP commands zero */
  pour_control_shape(&ctl, &out);
  TEST_ASSERT_EQUAL_INT16(0, out.torque);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_EQUAL_UINT16(POUR_FAULT_ESTOP, out.faults);
}

/* Continuity (docs/safety.md, transitions): the command moves by at most the slew limit a tick, or toward zero. */
static void assert_continuous(q15_t before, q15_t after) {
  const int32_t d = (int32_t)after - before;
  const bool toward_zero = (before >= 0 && after >= 0 && after <= before) || (before <= 0 && after <= 0 && after >= before);
  TEST_ASSERT_TRUE_MESSAGE((d <= config.safety.slew_per_tick && d >= -config.safety.slew_per_tick) || toward_zero,
                           "the command stepped beyond the slew limit");
}

/* One tick of an external controller that requests `torque` when a decision is due; returns the command. */
static q15_t external_tick(q15_t torque) {
  if (pour_control_update(&ctl, &in)) {
    pour_control_request(&ctl, 0u, torque);
  }
  pour_control_shape(&ctl, &out);
  return out.torque;
}

/* A run that ends at +0.4 tau_max, then Stop, Reset and the new run's first sample in one tick, and a first
 * decision across zero: the new run starts from the torque on the bus, through the slew limit (it used to
 * start from the safe torque: a step of 16,384 across zero). */
static void test_control_transitions_StopResetAndFirstSampleInOneTickKeepTheTorque(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &config, 1u));
  q15_t prev = 0;
  for (unsigned t = 0; t < 10u; ++t) {
    in.sensors_fresh = true;
    in.sensors.seq++;
    const q15_t now = external_tick(13107);
    assert_continuous(prev, now);
    prev = now;
  }
  TEST_ASSERT_EQUAL_INT16(13107, prev);
  in.stop = true;
  in.reset = true;
  in.sensors.seq++;
  const q15_t first = external_tick(-3277);
  in.stop = false;
  in.reset = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  assert_continuous(prev, first);
  TEST_ASSERT_EQUAL_INT16(13107 - config.safety.slew_per_tick, first);
}

/* A non-zero safe torque is reached through the slew limit from power-on's zero, and from the e-stop's zero
 * after a release, clear and reset in one tick. */
static void test_control_transitions_SafeTorqueIsReachedThroughTheSlew(void) {
  config.safe_torque = 10000;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  step(false);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_INT16(config.safety.slew_per_tick, out.torque);
  q15_t prev = out.torque;
  for (unsigned t = 0; t < 5u; ++t) {
    step(false);
    assert_continuous(prev, out.torque);
    prev = out.torque;
  }
  TEST_ASSERT_EQUAL_INT16(10000, out.torque);
  in.estop = true;
  step(true);
  TEST_ASSERT_EQUAL_INT16(0, out.torque);
  in.estop = false;
  in.clear_faults = true;
  in.reset = true;
  step(false);
  in.clear_faults = false;
  in.reset = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_INT16(config.safety.slew_per_tick, out.torque);
}

/* Tilts an external controller's bucket at 2 rad/s until the supervisor proves POSITION (past 140 deg):
 * FAULT with the active stop running. */
static void run_into_the_active_stop(void) {
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &config, 1u));
  memset(&out, 0, sizeof out); /* not the last test's output */
  int32_t theta = 0;
  for (unsigned t = 0; t < 2000u && out.mode != POUR_MODE_FAULT; ++t) {
    theta += 2000;
    sense(theta, FULL_G, 0);
    in.sensors_fresh = true;
    in.sensors.seq++;
    (void)external_tick(8000);
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_POSITION, out.faults);
  TEST_ASSERT_TRUE(out.power); /* the active stop */
}

/* A request in FAULT during the active stop (*request: in.reset or in.clear_faults) is refused like a Reset in
 * RUN: the braking goes on, unchanged, the faults stay latched and the estimate does not restart from rest (both
 * used to drop the stop's torque and restart the speed estimate while the bucket turned). */
static void assert_refused_during_the_active_stop(bool *request) {
  run_into_the_active_stop();
  pour_control_t without = ctl;
  pour_control_output_t out_without;
  in.sensors_fresh = true;
  in.sensors.seq++;
  pour_control_step(&without, &in, &out_without);
  const q15_t before = out.torque;
  const uint16_t faults = out.faults;
  *request = true;
  pour_control_step(&ctl, &in, &out);
  *request = false;
  TEST_ASSERT_EQUAL_UINT32(1u, out.refused);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_EQUAL_HEX16(faults, out.faults);
  TEST_ASSERT_TRUE(out.power);
  assert_continuous(before, out.torque);
  TEST_ASSERT_EQUAL_INT16(out_without.torque, out.torque);
  TEST_ASSERT_EQUAL_INT32(without.state.omega_urad_s, ctl.state.omega_urad_s);
}

static void test_control_transitions_ResetIsRefusedDuringTheActiveStop(void) {
  assert_refused_during_the_active_stop(&in.reset);
}

static void test_control_transitions_ClearIsRefusedDuringTheActiveStop(void) {
  assert_refused_during_the_active_stop(&in.clear_faults);
}

/* A Reset accepted once the stop is over restarts the run's state, not the motion: with fresh samples coming,
 * the brake keeps holding and the fault stays latched (it used to re-arm the active stop and release the
 * brake) until a clear. A Reset and a Stop every tick for a second change nothing of that. */
static void test_control_transitions_ResetOfAHeldAxisKeepsTheBrakeUntilAClear(void) {
  run_into_the_active_stop();
  const int32_t held = 2450000;
  sense(held, FULL_G, 0);
  for (unsigned t = 0; t < 6000u && out.power; ++t) {
    step(true);
  }
  TEST_ASSERT_TRUE(out.brake);
  for (unsigned t = 0; t < 1000u; ++t) {
    in.reset = true;
    in.stop = true;
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
    TEST_ASSERT_BITS_HIGH(POUR_FAULT_POSITION, out.faults);
    TEST_ASSERT_TRUE(out.brake);
    TEST_ASSERT_FALSE(out.power);
  }
  in.reset = false;
  in.stop = false;
  TEST_ASSERT_EQUAL_UINT32(1000u, out.refused); /* the Stops; each Reset was taken */
  in.clear_faults = true;
  step(false);
  in.clear_faults = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_UINT16(0u, out.faults);
}

/* Once the stop is over and the brake holds the bucket, a Reset is accepted, and the restarted estimator checks
 * its first sample against the last trusted angle: a 155 deg jump is BAD_INPUT, not a new run. */
static void test_control_transitions_RestartOfAHeldAxisRefusesAJump(void) {
  run_into_the_active_stop();
  const int32_t held = 2450000;
  sense(held, FULL_G, 0);
  for (unsigned t = 0; t < 6000u && out.power; ++t) {
    step(true); /* the bucket does not follow the stop: it ends at the stop's timeout, braked */
  }
  TEST_ASSERT_TRUE(out.brake);
  in.reset = true;
  step(false);
  in.reset = false;
  TEST_ASSERT_EQUAL_UINT32(0u, out.refused);
  sense(held - 2705260, FULL_G, 0); /* 155 deg away */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_BAD_INPUT, out.faults);
  /* A clear of the held axis checks the same way; with the bucket where it was, its sample is taken. */
  in.clear_faults = true;
  step(false);
  in.clear_faults = false;
  sense(held, FULL_G, 0);
  step(true);
  TEST_ASSERT_BITS_LOW(POUR_FAULT_BAD_INPUT, out.faults);
  TEST_ASSERT_INT32_WITHIN(1000, held, ctl.state.theta_urad);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_control_transitions_StopResetAndFirstSampleInOneTickKeepTheTorque);
  RUN_TEST(test_control_transitions_SafeTorqueIsReachedThroughTheSlew);
  RUN_TEST(test_control_transitions_ResetIsRefusedDuringTheActiveStop);
  RUN_TEST(test_control_transitions_ClearIsRefusedDuringTheActiveStop);
  RUN_TEST(test_control_transitions_RestartOfAHeldAxisRefusesAJump);
  RUN_TEST(test_control_transitions_ResetOfAHeldAxisKeepsTheBrakeUntilAClear);
  RUN_TEST(test_control_init_RefusesBadConfig);
  RUN_TEST(test_control_init_PassesOnAWeightsError);
  RUN_TEST(test_control_step_IdleWaitsForFirstStateWithoutTimingOut);
  RUN_TEST(test_control_step_FirstFreshSampleStartsRunAndDecides);
  RUN_TEST(test_control_step_GreedyProbabilitiesOnlyWhenAskedFor);
  RUN_TEST(test_control_step_DecidesEveryPeriodAndHoldsBetween);
  RUN_TEST(test_control_step_StaleInputAfterTimeoutGivesSafeTorqueAndLatches);
  RUN_TEST(test_control_step_ClearReturnsToIdleThenRun);
  RUN_TEST(test_control_step_EstopZeroesTorqueInTheSameTick);
  RUN_TEST(test_control_step_ImplausibleSamplesRaiseBadInput);
  RUN_TEST(test_control_step_BadInputInIdleAlsoFaults);
  RUN_TEST(test_control_step_VolumeSumCheckRefusesWhenArmed);
  RUN_TEST(test_control_step_EachRunStartsTheEstimateAfresh);
  RUN_TEST(test_control_stop_HoldsTheAxisWhileSamplesKeepComing);
  RUN_TEST(test_control_hold_AtBootNoRunUntilAReset);
  RUN_TEST(test_control_step_NoForwardTorquePastMaxAngle);
  RUN_TEST(test_control_step_IsDeterministic);
  RUN_TEST(test_control_request_OfThePolicysLevelsRepeatsItsRun);
  RUN_TEST(test_control_request_GoesThroughTheEnvelopeAndTheStop);
  return UNITY_END();
}
