/* SPDX-License-Identifier: MIT */
/* The identification experiments (pour/experiment.h) and their place in the control step. */
#include "pour/control.h"
#include "pour/experiment.h"
#include "unity.h"

static pour_control_config_t config;
static pour_control_t ctl;
static pour_control_input_t in;
static pour_control_output_t out;
static int64_t theta_nrad; /* the test's plant: an axis with inertia and damping [nrad], [nrad/s] */
static int64_t omega_nrad_s;

#define COUNTS 131072 /* the default 17-bit encoder */
#define TWO_PI_NRAD 6283185307LL

/* The encoder count of the plant's angle (below upright wraps). */
static uint32_t encoder_now(void) {
  const int64_t c = (theta_nrad * COUNTS) / TWO_PI_NRAD;
  return (uint32_t)((c % COUNTS + COUNTS) % COUNTS);
}

/* One tick: a fresh sample of the plant, the control step, then the plant moves 1 ms under the torque:
 * full torque gives 400 rad/s², the damping 2 /s. */
static void tick(void) {
  in.sensors_fresh = true;
  in.sensors.seq++;
  in.sensors.encoder = encoder_now();
  pour_control_step(&ctl, &in, &out);
  const int64_t alpha_nrad_s2 = (int64_t)out.torque * 400000000000LL / 32768 - 2 * omega_nrad_s;
  omega_nrad_s += alpha_nrad_s2 / 1000;
  theta_nrad += omega_nrad_s / 1000;
  in.stop = false;
  in.reset = false;
  in.clear_faults = false;
}

void setUp(void) {
  config = pour_control_default_config();
  /* The test's plant has no gravity and no friction: the supervisor's motion checks are tuned for the rig. */
  config.supervisor.checks = POUR_CHECK_POSITION | POUR_CHECK_OVERSPEED | POUR_CHECK_SEQ;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &config, 10u));
  in = (pour_control_input_t){0};
  in.sensors.scale_rotating_g = 10000; /* the estimator's volumes want some liquid to weigh */
  theta_nrad = 0;
  omega_nrad_s = 0;
}

void tearDown(void) {}

static void test_experiment_validate_RefusesBadConfig(void) {
  pour_experiment_config_t c = pour_experiment_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_experiment_validate(&c));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_experiment_validate(NULL));
  c.range_urad = c.hold_theta_urad - 1; /* upright would lie outside: it could never start */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_experiment_validate(&c));
  c = pour_experiment_default_config();
  c.chirp_f1_mhz = c.chirp_f0_mhz;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_experiment_validate(&c));
  c = pour_experiment_default_config();
  c.tilt_speed_urad_s = 3000000; /* beyond the envelope's speed limit */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_experiment_validate(&c));
  config.experiment.kp_per_rad = 0; /* the control step validates it at init */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init_external(&ctl, &config, 10u));
}

/* The identify phases in their order (the sweep, numbered after the ends, comes between chirp and back). */
static int identify_order(uint8_t phase) {
  return phase == POUR_EXPERIMENT_PHASE_SWEEP ? 2 * POUR_EXPERIMENT_PHASE_CHIRP + 1
                                              : (phase <= POUR_EXPERIMENT_PHASE_BACK ? 2 * phase : 100);
}

static void test_experiment_identify_RunsItsPhasesInOrderAndEndsHeld(void) {
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_ACCEPTED, pour_control_experiment_answer(&ctl));
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_NO_ANSWER, pour_control_experiment_answer(&ctl));
  const uint32_t duration = pour_experiment_duration_ms(&config.experiment, POUR_EXPERIMENT_IDENTIFY);
  uint8_t last = out.action;
  int32_t theta_max = 0;
  bool moved_both_ways = false;
  int64_t sweep_fastest = 0; /* [nrad/s] */
  int64_t sweep_fastest_back = 0;
  int32_t torque_min = 0;
  int32_t torque_max = 0;
  for (uint32_t t = 1; t < duration; ++t) {
    TEST_ASSERT_EQUAL_UINT16(0u, out.faults);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
    TEST_ASSERT_TRUE(identify_order(out.action) >= identify_order(last) && identify_order(out.action) < 100);
    if (out.action == POUR_EXPERIMENT_PHASE_SWEEP && omega_nrad_s > sweep_fastest) sweep_fastest = omega_nrad_s;
    if (out.action == POUR_EXPERIMENT_PHASE_SWEEP && -omega_nrad_s > sweep_fastest_back) sweep_fastest_back = -omega_nrad_s;
    last = out.action;
    if (out.torque < torque_min) torque_min = out.torque;
    if (out.torque > torque_max) torque_max = out.torque;
    const int32_t th = ctl.state.theta_urad;
    if (th > theta_max) theta_max = th;
    if (out.action == POUR_EXPERIMENT_PHASE_CHIRP && omega_nrad_s < 0 && th > 200000) moved_both_ways = true;
    tick();
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_EXPERIMENT_PHASE_BACK, last);
  TEST_ASSERT_TRUE(moved_both_ways);
  /* The sweep ran at its 1.5 rad/s both ways, within the envelope's 2 rad/s. */
  TEST_ASSERT_TRUE(sweep_fastest > 1400000000 && sweep_fastest < 2000000000);
  TEST_ASSERT_TRUE(sweep_fastest_back > 1400000000 && sweep_fastest_back < 2000000000);
  TEST_ASSERT_TRUE(torque_min < 0 && torque_max > 0);
  /* It stayed within its range about the hold angle, and came back to upright. */
  TEST_ASSERT_TRUE(theta_max > config.experiment.hold_theta_urad);
  TEST_ASSERT_TRUE(theta_max < config.experiment.hold_theta_urad + config.experiment.range_urad);
  tick();
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_UINT8(POUR_EXPERIMENT_PHASE_DONE, out.action);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_FALSE(out.power);
  /* Back near upright: the hold lags the ramp back by kd/kp * its speed (0.1 s * 0.23 rad/s). */
  TEST_ASSERT_INT_WITHIN(40000, 0, ctl.state.theta_urad);
  /* Held: fresh samples keep it in IDLE, braked, until a Reset. */
  for (int k = 0; k < 50; ++k) {
    tick();
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    TEST_ASSERT_TRUE(out.brake);
  }
  in.reset = true;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

static void test_experiment_Refused_InRunInEstopAndInFault(void) {
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_REFUSED_RUNNING, pour_control_experiment_answer(&ctl));
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT8(0u, out.action); /* the run's own decisions go on */
  in.estop = true;
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_REFUSED_ESTOP, pour_control_experiment_answer(&ctl));
  in.estop = false;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_REFUSED_FAULT, pour_control_experiment_answer(&ctl));
  pour_control_experiment(&ctl, POUR_EXPERIMENT_KIND_MAX + 1u);
  in.clear_faults = true;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_REFUSED_KIND, pour_control_experiment_answer(&ctl));
}

static void test_experiment_StopAndStartInOneTick_Starts(void) {
  tick();
  in.stop = true;
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_ACCEPTED, pour_control_experiment_answer(&ctl));
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT8(POUR_EXPERIMENT_PHASE_RAMP, out.action);
}

static void test_experiment_LeavingTheRange_EndsItHeld(void) {
  config.experiment.range_urad = config.experiment.hold_theta_urad; /* [0, 2 hold]: below upright is out */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init_external(&ctl, &config, 10u));
  theta_nrad = 10000000; /* 10 mrad, falling back at 1 rad/s: past upright within ~10 ms */
  omega_nrad_s = -1000000000;
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  int k = 0;
  do {
    tick();
  } while (out.mode == POUR_MODE_RUN && ++k < 100);
  TEST_ASSERT_TRUE(k > 2);
  TEST_ASSERT_EQUAL_UINT16(0u, out.faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_UINT8(POUR_EXPERIMENT_PHASE_OUT_OF_RANGE, out.action);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_TRUE(ctl.state.theta_urad < 0);
}

static void test_experiment_StopEndsItHeld_AndAFaultEndsItForGood(void) {
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  for (int k = 0; k < 100; ++k) tick();
  in.stop = true;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode); /* held */
  TEST_ASSERT_TRUE(out.brake);
  /* Armed again, then a fault before it ran: it is gone, and a clear does not bring it back. */
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  in.estop = true;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_REFUSED_ESTOP, pour_control_experiment_answer(&ctl));
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  in.estop = false;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_CONTROL_EXPERIMENT_REFUSED_FAULT, pour_control_experiment_answer(&ctl));
  in.clear_faults = true;
  tick();
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode); /* still held: only a Reset releases it */
  in.reset = true;
  tick();
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT8(0u, out.action); /* the run's own decisions */
}

static void test_experiment_tilt_TracksTheSlowTiltAndComesBack(void) {
  pour_control_experiment(&ctl, POUR_EXPERIMENT_TILT);
  const uint32_t duration = pour_experiment_duration_ms(&config.experiment, POUR_EXPERIMENT_TILT);
  int32_t theta_max = 0;
  for (uint32_t t = 0; t < duration + 2u; ++t) {
    tick();
    if (ctl.state.theta_urad > theta_max) theta_max = ctl.state.theta_urad;
    if (out.action == POUR_EXPERIMENT_PHASE_TILT && t > 100u) {
      /* On the ramp: within 2 deg of it, at about the tilt speed. */
      TEST_ASSERT_INT_WITHIN(35000, (int32_t)(t * 100u), ctl.state.theta_urad);
    }
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_UINT8(POUR_EXPERIMENT_PHASE_DONE, out.action);
  TEST_ASSERT_INT_WITHIN(35000, config.experiment.tilt_theta_urad, theta_max);
  TEST_ASSERT_INT_WITHIN(35000, 0, ctl.state.theta_urad);
}

static void test_experiment_identify_RunsOnAnEmptyBucket_ARunAfterAResetDoesNot(void) {
  in.sensors.scale_rotating_g = 0; /* empty, as the identify experiment wants it */
  tick();
  TEST_ASSERT_EQUAL_UINT16(POUR_FAULT_BAD_INPUT, out.faults); /* a run needs liquid to weigh */
  in.clear_faults = true;
  pour_control_experiment(&ctl, POUR_EXPERIMENT_IDENTIFY);
  for (int k = 0; k < 200; ++k) tick();
  TEST_ASSERT_EQUAL_UINT16(0u, out.faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_INT16(0, ctl.state.v_spill); /* nothing to spill */
  in.stop = true;
  tick();
  tick();
  TEST_ASSERT_EQUAL_UINT16(0u, out.faults); /* held, empty */
  in.reset = true;
  tick();
  TEST_ASSERT_EQUAL_UINT16(POUR_FAULT_BAD_INPUT, out.faults);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_experiment_validate_RefusesBadConfig);
  RUN_TEST(test_experiment_identify_RunsItsPhasesInOrderAndEndsHeld);
  RUN_TEST(test_experiment_Refused_InRunInEstopAndInFault);
  RUN_TEST(test_experiment_StopAndStartInOneTick_Starts);
  RUN_TEST(test_experiment_LeavingTheRange_EndsItHeld);
  RUN_TEST(test_experiment_StopEndsItHeld_AndAFaultEndsItForGood);
  RUN_TEST(test_experiment_tilt_TracksTheSlowTiltAndComesBack);
  RUN_TEST(test_experiment_identify_RunsOnAnEmptyBucket_ARunAfterAResetDoesNot);
  return UNITY_END();
}
