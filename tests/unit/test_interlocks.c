/* SPDX-License-Identifier: MIT */
/* Every transition of the core that releases the brake, powers the stage or starts motion, with each input
 * of its tick that must veto it, alone (docs/hazards.md, "Transitions that release the brake"):
 *   IDLE -> RUN on the first fresh sample: the e-stop, the link fault, the drive's fault word, a sample out
 *     of range, a sample that does not advance, an axis held after an experiment, a clear refused;
 *   a clear (FAULT -> IDLE): the e-stop, the link fault, the drive's fault word, the active stop running;
 *   the active stop (FAULT with the power on): a drive that no longer follows a torque, a fault that is not
 *     a motion fault, no fresh sample;
 *   an experiment's start: RUN, FAULT, the e-stop, an unknown kind, and then the vetoes of RUN.
 * Each case runs the same tick twice, once with the veto and once without, so that the test shows the
 * transition happens when nothing vetoes it. */
#include <string.h>

#include "pour/control.h"
#include "pour/params.h"
#include "pour/weights_compiled.h"
#include "unity.h"

static pour_control_config_t config;
static pour_control_t ctl;
static pour_control_input_t in;
static pour_control_output_t out;

#define FULL_G 10000

static uint32_t count_at(int32_t theta_urad) {
  const int64_t c = ((int64_t)theta_urad * 131072 * 1000 + (theta_urad >= 0 ? 3141592654LL : -3141592654LL)) /
                    6283185307LL;
  return (uint32_t)((c + 131072) % 131072);
}

static void step(bool fresh) {
  in.sensors_fresh = fresh;
  if (fresh) {
    in.sensors.seq++;
  }
  pour_control_step(&ctl, &in, &out);
}

static void quiet_inputs(void) {
  in.estop = in.clear_faults = in.link_fault = in.stop = in.reset = false;
  in.drive_faults = 0u;
  in.drive_trusted = true;
}

void setUp(void) {
  config = pour_control_default_config();
  /* Scripted samples of a bucket that does not move under torque: only the checks that need no physics. */
  config.supervisor.checks = POUR_CHECK_POSITION | POUR_CHECK_OVERSPEED | POUR_CHECK_SEQ;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  memset(&in, 0, sizeof in);
  quiet_inputs();
  in.sensors.encoder = count_at(0);
  in.sensors.scale_rotating_g = FULL_G;
}

void tearDown(void) {}

static void assert_held(void) {
  TEST_ASSERT_TRUE(out.mode == POUR_MODE_FAULT || out.mode == POUR_MODE_IDLE || out.mode == POUR_MODE_ESTOP);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_FALSE(out.power);
}

/* A latched fault whose stop is over: RUN, then a stale link for longer than the timeout, then the brake. */
static void fault_and_stop(void) {
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  for (unsigned i = 0; i <= config.input_timeout_ms; ++i) step(false);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  assert_held();
}

/* The veto inputs of a tick, one at a time; 0 is none. */
enum { VETO_NONE, VETO_ESTOP, VETO_LINK, VETO_DRIVE, VETO_OUT_OF_RANGE, VETO_NOT_ADVANCING, VETO_COUNT };

static void apply(int veto) {
  quiet_inputs();
  in.estop = veto == VETO_ESTOP;
  in.link_fault = veto == VETO_LINK;
  in.drive_faults = veto == VETO_DRIVE ? 0x0008u /* UNDERVOLTAGE */ : 0u;
  in.sensors.encoder = veto == VETO_OUT_OF_RANGE ? 1u << 17 : count_at(0);
}

static void fresh_or_repeated(int veto) {
  if (veto == VETO_NOT_ADVANCING) {
    in.sensors_fresh = true; /* the same seq again: a frozen sender, not a new sample */
    pour_control_step(&ctl, &in, &out);
  } else {
    step(true);
  }
}

static void test_interlock_RunStartsOnlyWhenNoInputOfTheTickVetoesIt(void) {
  for (int veto = VETO_NONE; veto < VETO_COUNT; ++veto) {
    setUp();
    step(false); /* power-on: IDLE, nothing yet */
    if (veto == VETO_NOT_ADVANCING) {
      step(true);
      in.stop = true; /* back to IDLE, the last seq kept */
      step(false);
      in.stop = false;
      TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    }
    apply(veto);
    fresh_or_repeated(veto);
    if (veto == VETO_NONE) {
      TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
      TEST_ASSERT_TRUE(out.power && !out.brake);
    } else {
      assert_held();
    }
  }
}

/* A clear in a tick whose link or drive fault is still asserted is refused: the brake holds in that tick and
 * every later one, however many clears come with fresh samples, and the first tick without the level takes
 * the clear (IDLE) and the next sample RUN. */
static void test_interlock_AClearNeverReleasesWhileALevelFaultIsAsserted(void) {
  for (int veto = VETO_LINK; veto <= VETO_DRIVE; ++veto) {
    setUp();
    fault_and_stop();
    const uint32_t refused = out.refused;
    for (unsigned t = 0; t < 500u; ++t) {
      apply(veto);
      in.clear_faults = true; /* a clear every tick, with a fresh sample in every tick */
      step(true);
      TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
      assert_held();
      TEST_ASSERT_EQUAL_UINT32(refused + t + 1u, out.refused); /* each one refused, and counted */
    }
    apply(VETO_NONE);
    in.clear_faults = true;
    step(false);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
    in.clear_faults = false;
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  }
}

/* A clear in the very tick a drive fault appears in RUN (the tick it latches, the stop not yet begun). */
static void test_interlock_AClearInTheTickOfADriveFaultIsRefused(void) {
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  in.drive_faults = 0x0001u; /* OVERCURRENT */
  in.drive_trusted = false;
  in.clear_faults = true;
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_DRIVE, out.faults);
  assert_held();
}

/* What a port with a drive asks before handing it a clear (board_drive.c): each veto alone says no. */
static void test_interlock_ClearAcceptableNamesEachVeto(void) {
  fault_and_stop();
  apply(VETO_NONE);
  TEST_ASSERT_TRUE(pour_control_clear_acceptable(&ctl, &in));
  in.estop = true;
  TEST_ASSERT_FALSE(pour_control_clear_acceptable(&ctl, &in));
  apply(VETO_LINK);
  TEST_ASSERT_FALSE(pour_control_clear_acceptable(&ctl, &in));
  setUp();
  step(true); /* RUN: nothing to clear */
  TEST_ASSERT_FALSE(pour_control_clear_acceptable(&ctl, &in));
}

/* The active stop powers the stage: only while the drive follows a torque, the fault is a motion fault and
 * fresh samples come. A bucket past the position limit with the drive trusted stops actively; untrusted,
 * or with BAD_INPUT beside it, or with the samples stopping, the brake holds at once. */
static void test_interlock_TheActiveStopRunsOnlyWhenNothingVetoesIt(void) {
  for (int veto = 0; veto < 4; ++veto) {
    setUp();
    config.safety.theta_max_urad = 200000; /* a limit the scripted bucket can pass */
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
    in.sensors.encoder = count_at(100000);
    step(true);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
    for (int32_t th = 102000; th <= 600000 && out.mode == POUR_MODE_RUN; th += 2000) {
      in.sensors.encoder = count_at(th); /* on past the limit and its margin: a motion fault */
      step(true);
    }
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
    TEST_ASSERT_EQUAL_HEX16(0u, out.faults & (uint16_t)~POUR_FAULT_ACTIVE_STOP);
    in.drive_faults = veto == 1 ? 0x0010u : 0u; /* OVERTEMP ... */
    in.drive_trusted = veto != 1;              /* ... with the phases shorted */
    if (veto == 2) in.sensors.scale_rotating_g = 1 << 30; /* and a scale no sensor can read: BAD_INPUT */
    step(veto != 3);
    for (int t = 0; t < 30; ++t) step(veto != 3); /* the stop on fresh samples, or the samples stopping */
    if (veto == 0) {
      TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
      TEST_ASSERT_TRUE(out.power && !out.brake);
    } else {
      assert_held();
    }
  }
}

/* An experiment starts only from IDLE with nothing latched; a Stop of the run before it does not count. */
static void test_interlock_AnExperimentStartsOnlyFromACleanIdle(void) {
  for (int veto = 0; veto < 5; ++veto) {
    setUp();
    step(false);
    if (veto == 1) fault_and_stop();   /* FAULT */
    if (veto == 2) step(true);         /* RUN */
    in.estop = veto == 3;
    pour_control_experiment(&ctl, veto == 4 ? 200u : (uint8_t)POUR_EXPERIMENT_IDENTIFY);
    in.sensors.scale_rotating_g = 0;
    step(true);
    const uint8_t answer = pour_control_experiment_answer(&ctl);
    if (veto == 0) {
      TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_ACCEPTED, answer);
      step(true);
      TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
    } else {
      TEST_ASSERT_NOT_EQUAL(POUR_CONTROL_EXPERIMENT_ACCEPTED, answer);
      if (veto != 2) assert_held();
    }
  }
}

/* An armed experiment's first sample is the RUN entry of any run: each of its vetoes keeps the axis held. */
static void test_interlock_AnArmedExperimentKeepsEveryVetoOfRun(void) {
  for (int veto = VETO_ESTOP; veto < VETO_NOT_ADVANCING; ++veto) {
    setUp();
    step(false);
    pour_control_experiment(&ctl, (uint8_t)POUR_EXPERIMENT_IDENTIFY);
    step(false);
    TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_ACCEPTED, pour_control_experiment_answer(&ctl));
    apply(veto);
    in.sensors.scale_rotating_g = 0;
    step(true);
    assert_held();
  }
}

/* An experiment that ends on its first sample (the bucket outside its range, at the envelope's limit) leaves
 * the axis held in IDLE with the command on the way to the safe torque: zero while the safe torque would push
 * past the limit, the safe torque once the bucket is back inside (docs/safety.md, Modes). */
static void test_interlock_AnExperimentEndingOnItsFirstSampleHoldsTowardTheSafeTorque(void) {
  config.safe_torque = 3000;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  in.sensors.scale_rotating_g = 0;
  for (int t = 0; t < 20; ++t) step(false);
  TEST_ASSERT_EQUAL_INT16(3000, out.torque);
  pour_control_experiment(&ctl, (uint8_t)POUR_EXPERIMENT_IDENTIFY);
  in.sensors.encoder = count_at(config.safety.theta_max_urad + 1000);
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_ACCEPTED, pour_control_experiment_answer(&ctl));
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_EQUAL_INT16(0, out.torque); /* no forward torque past the limit */
  in.sensors.encoder = count_at(0);
  for (int t = 0; t < 5; ++t) step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode); /* held: no run starts by itself */
  TEST_ASSERT_EQUAL_INT16(3000, out.torque);
}

/* A parameter write puts a new configuration in force through pour_control_init (pour_params_apply): it must
 * not end the hold that an experiment's end left (only a Reset or another experiment does). */
static void test_interlock_AParameterWriteKeepsTheHoldAfterAnExperiment(void) {
  in.sensors.scale_rotating_g = 0;
  step(false);
  pour_control_experiment(&ctl, (uint8_t)POUR_EXPERIMENT_IDENTIFY);
  in.sensors.encoder = count_at(config.safety.theta_max_urad + 1000); /* outside its range: it ends at once */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  pour_params_t params;
  pour_params_default(&params, &config, 1u);
  params.control.safety.omega_max_urad_s = 1500000;
  TEST_ASSERT_TRUE(pour_params_writable(&ctl));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  in.sensors.encoder = count_at(0);
  for (int t = 0; t < 50; ++t) {
    step(true);
    TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    assert_held();
  }
}

/* ... nor forget the angle the brake held: after a write in FAULT, the first sample after the clear must still
 * lie within restart_jump_max of the last trusted angle, or it is BAD_INPUT. */
static void test_interlock_AParameterWriteInFaultKeepsTheRestartCheck(void) {
  fault_and_stop();
  pour_params_t params;
  pour_params_default(&params, &config, 1u);
  params.control.safety.omega_max_urad_s = 1500000;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_params_apply(&ctl, &params, &pour_weights_compiled));
  in.clear_faults = true;
  step(false);
  in.clear_faults = false;
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  in.sensors.encoder = count_at(2 * config.restart_jump_max_urad); /* it moved under the brake */
  step(true);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_BAD_INPUT, out.faults);
  assert_held();
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_interlock_RunStartsOnlyWhenNoInputOfTheTickVetoesIt);
  RUN_TEST(test_interlock_AClearNeverReleasesWhileALevelFaultIsAsserted);
  RUN_TEST(test_interlock_AClearInTheTickOfADriveFaultIsRefused);
  RUN_TEST(test_interlock_ClearAcceptableNamesEachVeto);
  RUN_TEST(test_interlock_TheActiveStopRunsOnlyWhenNothingVetoesIt);
  RUN_TEST(test_interlock_AnExperimentStartsOnlyFromACleanIdle);
  RUN_TEST(test_interlock_AnArmedExperimentKeepsEveryVetoOfRun);
  RUN_TEST(test_interlock_AnExperimentEndingOnItsFirstSampleHoldsTowardTheSafeTorque);
  RUN_TEST(test_interlock_AParameterWriteKeepsTheHoldAfterAnExperiment);
  RUN_TEST(test_interlock_AParameterWriteInFaultKeepsTheRestartCheck);
  return UNITY_END();
}
