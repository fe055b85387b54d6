/* SPDX-License-Identifier: MIT */
/* The supervisor inside the control step, one test per fault, against a small fixed-point plant (a rigid
 * bucket, 200 rad/s² at full torque, hard stops at -90 deg and 135 deg): each fault is injected the way it
 * shows in the data, and it must be named within 50 ticks, with the torque inside the envelope and never
 * stepping by more than the slew limit except to zero. */
#include <stdbool.h>

#include "pour/control.h"
#include "pour/weights_compiled.h"
#include "unity.h"

#define DETECT_TICKS_MAX 50u
#define THETA_STOP_LOW (-1570796)
#define THETA_STOP_HIGH 2356194
#define OMEGA_PER_Q15_TICK 6 /* µrad/s per tick per Q15 LSB of torque: full torque ≈ 197 rad/s² */

typedef struct {
  int32_t theta_urad;
  int32_t omega_urad_s;
  int32_t motor_sign;   /* -1: the motor turns the other way */
  int32_t encoder_sign; /* -1: the encoder counts the other way */
  bool encoder_frozen;
  int32_t frozen_theta, frozen_omega;
  uint32_t seq;
  bool sender_frozen;
  q15_t v_rotating;
  int32_t gain;         /* 1, or more: the drive's torque scale stuck high */
} plant_t;

static pour_control_config_t config;
static pour_control_t ctl;
static pour_control_output_t out;
static plant_t plant;
static q15_t last_torque;

void setUp(void) {
  config = pour_control_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  const plant_t p = {0, 0, 1, 1, false, 0, 0, 0u, false, 32767, 1};
  plant = p;
  last_torque = 0;
}

void tearDown(void) {}

static void plant_step(q15_t torque) {
  plant.omega_urad_s += plant.motor_sign * plant.gain * torque * OMEGA_PER_Q15_TICK;
  plant.theta_urad += plant.omega_urad_s / 1000;
  if (plant.theta_urad >= THETA_STOP_HIGH || plant.theta_urad <= THETA_STOP_LOW) {
    plant.theta_urad = plant.theta_urad >= THETA_STOP_HIGH ? THETA_STOP_HIGH : THETA_STOP_LOW;
    plant.omega_urad_s = 0;
  }
}

/* One tick: the plant's reading (through the injected faults), the control step, the envelope's bars. */
static void tick(void) {
  pour_control_input_t in = {0};
  in.state_fresh = true;
  if (!plant.sender_frozen) {
    plant.seq++;
  }
  in.state.seq = plant.seq;
  in.state.theta_urad = plant.encoder_frozen ? plant.frozen_theta : plant.encoder_sign * plant.theta_urad;
  in.state.omega_urad_s = plant.encoder_frozen ? plant.frozen_omega : plant.encoder_sign * plant.omega_urad_s;
  in.state.v_rotating = plant.v_rotating;
  pour_control_step(&ctl, &in, &out);
  const int32_t step = (int32_t)out.torque - last_torque;
  TEST_ASSERT_TRUE(out.torque == 0 || (step <= config.safety.slew_per_tick && step >= -config.safety.slew_per_tick));
  TEST_ASSERT_TRUE(out.torque <= config.safety.tau_limit && out.torque >= -config.safety.tau_limit);
  last_torque = out.torque;
  plant_step(out.power ? out.torque : 0);
}

/* Runs until the fault bit shows (or the tick limit), returns the ticks it took. */
static uint32_t ticks_until(uint16_t fault, uint32_t limit) {
  for (uint32_t t = 1; t <= limit; ++t) {
    tick();
    if ((out.faults & fault) != 0u) {
      return t;
    }
  }
  return limit + 1u;
}

static void run_ticks(uint32_t n) {
  for (uint32_t t = 0; t < n; ++t) {
    tick();
  }
}

static void test_supervisor_RightPlantRaisesNoFault(void) {
  run_ticks(600u);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_HEX16(0, out.faults);
  TEST_ASSERT_TRUE(plant.theta_urad > 1500000); /* the policy did pour: the checks saw real motion */
}

static void test_supervisor_ReversedMotorIsATorqueSignFaultWithin50Ticks(void) {
  plant.motor_sign = -1;
  const uint32_t t = ticks_until(POUR_FAULT_TORQUE_SIGN | POUR_FAULT_POSITION, 200u);
  TEST_ASSERT_TRUE(t <= DETECT_TICKS_MAX);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_TORQUE_SIGN, out.faults);
  TEST_ASSERT_TRUE(out.brake); /* the motor cannot be trusted: brake and power cut at once */
  TEST_ASSERT_FALSE(out.power);
  TEST_ASSERT_EQUAL_INT16(0, out.torque);
}

static void test_supervisor_ReversedEncoderIsCaughtWithin50Ticks(void) {
  plant.encoder_sign = -1;
  const uint32_t t = ticks_until(POUR_FAULT_TORQUE_SIGN | POUR_FAULT_POSITION, 200u);
  TEST_ASSERT_TRUE(t <= DETECT_TICKS_MAX);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_TRUE(out.brake);
}

static void test_supervisor_FrozenEncoderUnderTorqueIsCaughtWithin50Ticks(void) {
  run_ticks(5u);
  plant.encoder_frozen = true;
  plant.frozen_theta = plant.theta_urad;
  plant.frozen_omega = plant.omega_urad_s;
  const uint32_t t = ticks_until(POUR_FAULT_ENCODER, 200u);
  TEST_ASSERT_TRUE(t <= DETECT_TICKS_MAX);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_FALSE(out.power);
}

static void test_supervisor_ScaleStuckHighIsCaughtWithin50Ticks(void) {
  plant.gain = 10; /* 2,000 rad/s² at full torque: ten times what the motor can give the lightest load */
  const uint32_t t = ticks_until(POUR_FAULT_SCALE | POUR_FAULT_OVERSPEED, 200u);
  TEST_ASSERT_TRUE(t <= DETECT_TICKS_MAX);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
}

static void test_supervisor_FrozenSenderIsStaleAndSeqWithinTheTimeout(void) {
  run_ticks(30u);
  plant.sender_frozen = true; /* the same frame again and again, every tick */
  const uint32_t t = ticks_until(POUR_FAULT_STALE_INPUT, 200u);
  TEST_ASSERT_EQUAL_UINT32(config.input_timeout_ms + 1u, t);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_SEQ, out.faults);
  TEST_ASSERT_TRUE(out.brake);
}

static void test_supervisor_LostStatesAreNotAFault(void) {
  for (uint32_t t = 0; t < 400u; ++t) {
    if (t % 10u == 3u) { /* 10 % lost: the seq skips one, the tick runs on the last state */
      pour_control_input_t in = {0};
      in.state = ctl.state;
      plant.seq++;
      pour_control_step(&ctl, &in, &out);
      const int32_t step = (int32_t)out.torque - last_torque;
      TEST_ASSERT_TRUE(step <= config.safety.slew_per_tick && step >= -config.safety.slew_per_tick);
      last_torque = out.torque;
      plant_step(out.power ? out.torque : 0);
    } else {
      tick();
    }
  }
  TEST_ASSERT_EQUAL_HEX16(0, out.faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

static void test_supervisor_VolumeJumpIsCaughtAtOnce(void) {
  run_ticks(30u);
  plant.v_rotating = (q15_t)(plant.v_rotating - 6554); /* 20 % of the liquid gone in 1 ms */
  TEST_ASSERT_EQUAL_UINT32(1u, ticks_until(POUR_FAULT_VOLUME, 10u));
}

static void test_supervisor_OverspeedStopsActivelyThenBrakes(void) {
  run_ticks(20u);
  plant.omega_urad_s = 25000000; /* a runaway: 25 rad/s */
  TEST_ASSERT_EQUAL_UINT32(1u, ticks_until(POUR_FAULT_OVERSPEED, 10u));
  /* The sensors and the motor are trusted: decelerate with power on, brake off ... */
  const q15_t before = out.torque;
  tick();
  TEST_ASSERT_TRUE(out.power);
  TEST_ASSERT_FALSE(out.brake);
  TEST_ASSERT_TRUE(out.torque < before);
  /* ... back toward upright at a bounded speed, then brake once at rest. */
  int32_t peak_back = 0;
  for (uint32_t t = 0; t < 6000u && out.power; ++t) {
    tick();
    if (plant.omega_urad_s < peak_back) {
      peak_back = plant.omega_urad_s;
    }
  }
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_FALSE(out.power);
  TEST_ASSERT_TRUE(plant.theta_urad <= config.stop.rest_theta_urad && plant.theta_urad >= -config.stop.rest_theta_urad);
  TEST_ASSERT_TRUE(peak_back >= -2 * config.stop.return_speed_urad_s);
}

static void test_supervisor_PositionPastTheMarginIsCaught(void) {
  run_ticks(10u);
  plant.theta_urad = config.safety.theta_min_urad - config.supervisor.theta_margin_urad - 1000;
  plant.omega_urad_s = 0;
  TEST_ASSERT_EQUAL_UINT32(1u, ticks_until(POUR_FAULT_POSITION, 10u));
}

static void test_supervisor_ClearAfterAStopRampsThroughSlewAndRunsAgain(void) {
  plant.motor_sign = -1;
  (void)ticks_until(POUR_FAULT_TORQUE_SIGN, 200u);
  plant.motor_sign = 1;
  pour_control_input_t in = {0};
  in.clear_faults = true;
  in.state = ctl.state;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  last_torque = out.torque;
  run_ticks(50u); /* tick() checks the slew on every step */
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

/* The seq check follows the count outside RUN too: after 40 s in FAULT (more than the 32,767-sample window
 * of a forward step), a clear still lets the run resume. */
static void test_supervisor_LongFaultThenClearStillResumes(void) {
  run_ticks(20u);
  pour_control_input_t in = {0};
  in.estop = true;
  pour_control_step(&ctl, &in, &out);
  in.estop = false;
  in.state_fresh = true;
  in.state = ctl.state;
  for (uint32_t t = 0; t < 40000u; ++t) {
    in.state.seq = ++plant.seq;
    pour_control_step(&ctl, &in, &out);
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  in.clear_faults = true;
  in.state.seq = ++plant.seq;
  pour_control_step(&ctl, &in, &out);
  in.clear_faults = false;
  in.state.seq = ++plant.seq;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

static void test_supervisor_init_RefusesBadConfig(void) {
  config.supervisor.window_ms = 1u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.supervisor.window_ms = POUR_SUPERVISOR_WINDOW_MAX + 1u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.supervisor.checks = 0x80u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
  config = pour_control_default_config();
  config.stop.timeout_ms = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_control_init(&ctl, &config, &pour_weights_compiled));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_supervisor_RightPlantRaisesNoFault);
  RUN_TEST(test_supervisor_ReversedMotorIsATorqueSignFaultWithin50Ticks);
  RUN_TEST(test_supervisor_ReversedEncoderIsCaughtWithin50Ticks);
  RUN_TEST(test_supervisor_FrozenEncoderUnderTorqueIsCaughtWithin50Ticks);
  RUN_TEST(test_supervisor_ScaleStuckHighIsCaughtWithin50Ticks);
  RUN_TEST(test_supervisor_FrozenSenderIsStaleAndSeqWithinTheTimeout);
  RUN_TEST(test_supervisor_LostStatesAreNotAFault);
  RUN_TEST(test_supervisor_VolumeJumpIsCaughtAtOnce);
  RUN_TEST(test_supervisor_OverspeedStopsActivelyThenBrakes);
  RUN_TEST(test_supervisor_PositionPastTheMarginIsCaught);
  RUN_TEST(test_supervisor_ClearAfterAStopRampsThroughSlewAndRunsAgain);
  RUN_TEST(test_supervisor_LongFaultThenClearStillResumes);
  RUN_TEST(test_supervisor_init_RefusesBadConfig);
  return UNITY_END();
}
