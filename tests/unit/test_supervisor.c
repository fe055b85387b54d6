/* SPDX-License-Identifier: MIT */
/* The supervisor inside the control step, one test per fault, against a small fixed-point plant (a rigid
 * bucket, 200 rad/s² at full torque, hard stops at -90 deg and 135 deg) read through the rig's sensors (a
 * 17-bit encoder, load cells that update at 80 Hz and hold in between): each fault is injected the way it
 * shows in the samples, and it must be named within 50 ticks, with the torque inside the envelope and never
 * stepping by more than the slew limit except to zero. */
#include <stdbool.h>

#include "pour/control.h"
#include "pour/weights_compiled.h"
#include "unity.h"

#define DETECT_TICKS_MAX 50u
#define THETA_STOP_LOW (-1570796)
#define THETA_STOP_HIGH 2356194
#define OMEGA_PER_Q15_TICK 6 /* µrad/s per tick per Q15 LSB of torque: full torque ≈ 197 rad/s² */
#define LIQUID_G 10000       /* 10 kg */
#define SCALE_PERIOD_TICKS 12u /* an 80 Hz load cell */

typedef struct {
  int32_t theta_urad;
  int32_t omega_urad_s;
  int32_t motor_sign;   /* -1: the motor turns the other way */
  int32_t encoder_sign; /* -1: the encoder counts the other way */
  bool encoder_frozen;
  uint32_t frozen_count;
  uint32_t seq;
  bool sender_frozen;
  int32_t m_rot_g, m_tgt_g;     /* the liquid where it is [g] */
  int32_t flow_g_per_tick;      /* poured from the rotating bucket into the target each tick [g] */
  int32_t held_rot_g, held_tgt_g; /* what the load cells show: updated every SCALE_PERIOD_TICKS */
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
  const plant_t p = {0, 0, 1, 1, false, 0u, 0u, false, LIQUID_G, 0, 0, LIQUID_G, 0, 1};
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

/* The raw count of the 17-bit encoder at θ [µrad], rounded, wrapped below upright. */
static uint32_t count_at(int32_t theta_urad) {
  const int64_t c = ((int64_t)theta_urad * 131072 * 1000 + (theta_urad >= 0 ? 3141592654LL : -3141592654LL)) /
                    6283185307LL;
  return (uint32_t)((c + 131072) % 131072);
}

/* What the sensors read now (through the injected faults). */
static pour_sensors_t sample_now(void) {
  if (!plant.sender_frozen) {
    plant.seq++;
    plant.m_rot_g -= plant.flow_g_per_tick;
    plant.m_tgt_g += plant.flow_g_per_tick;
    if (plant.seq % SCALE_PERIOD_TICKS == 0u) {
      plant.held_rot_g = plant.m_rot_g;
      plant.held_tgt_g = plant.m_tgt_g;
    }
  }
  const uint32_t count = plant.encoder_frozen ? plant.frozen_count : count_at(plant.encoder_sign * plant.theta_urad);
  const pour_sensors_t s = {plant.seq, count, plant.held_rot_g, plant.held_tgt_g};
  return s;
}

/* The envelope's bars on this tick's command: within ±tau_limit; a step beyond the slew only toward zero
 * (less torque never waits); and never a torque that speeds the bucket up beyond ±omega_max, judged on the
 * speed the controller estimated (the only one it has): τ <= max(K (ω_max - θ̇), 0) and
 * τ >= min(-K (ω_max + θ̇), 0), K = governor_gain per rad/s, ±1 LSB for rounding. */
static void check_envelope(void) {
  const pour_safety_config_t *sc = &config.safety;
  const int32_t t = out.torque;
  const int32_t step = t - last_torque;
  const bool toward_zero =
      (last_torque >= 0 && t >= 0 && t <= last_torque) || (last_torque <= 0 && t <= 0 && t >= last_torque);
  TEST_ASSERT_TRUE(toward_zero || (step <= sc->slew_per_tick && step >= -sc->slew_per_tick));
  TEST_ASSERT_TRUE(t <= sc->tau_limit && t >= -sc->tau_limit);
  const int64_t w = ctl.state.omega_urad_s;
  const int64_t hi = ((int64_t)sc->omega_max_urad_s - w) * sc->governor_gain / 1000000;
  const int64_t lo = (-(int64_t)sc->omega_max_urad_s - w) * sc->governor_gain / 1000000;
  TEST_ASSERT_TRUE(t <= (hi > 0 ? hi : 0) + 1);
  TEST_ASSERT_TRUE(t >= (lo < 0 ? lo : 0) - 1);
  last_torque = out.torque;
}

/* One tick: the plant's reading, the control step, the envelope's bars. */
static void tick(void) {
  pour_control_input_t in = {0};
  in.sensors_fresh = true;
  in.sensors = sample_now();
  pour_control_step(&ctl, &in, &out);
  check_envelope();
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
  plant.flow_g_per_tick = 8; /* 0.08 % a tick, shown by the scales in steps of 1 % every 12 ticks */
  int32_t peak = 0;
  for (uint32_t t = 0; t < 1200u; ++t) {
    tick();
    peak = plant.omega_urad_s > peak ? plant.omega_urad_s : peak;
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_HEX16(0, out.faults);
  TEST_ASSERT_TRUE(plant.theta_urad > 1200000); /* the policy did pour: the checks saw real motion */
  TEST_ASSERT_TRUE(peak > 1900000);             /* up to the speed limit ... */
  TEST_ASSERT_TRUE(peak <= config.safety.omega_max_urad_s + 50000); /* ... and no further */
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
  plant.frozen_count = count_at(plant.theta_urad);
  const uint32_t t = ticks_until(POUR_FAULT_ENCODER, 200u);
  TEST_ASSERT_TRUE(t <= DETECT_TICKS_MAX);
  TEST_ASSERT_TRUE(out.brake);
  TEST_ASSERT_FALSE(out.power);
}

/* A torque scale stuck high (10 times: 2,000 rad/s² at full torque, ten times what the motor can give the
 * lightest load). With the motion envelope the governor closes the loop on the speed and contains it: the
 * bucket stays within the speed band ... */
static void test_supervisor_ScaleStuckHighIsContainedByTheSpeedBand(void) {
  plant.gain = 10;
  for (uint32_t t = 0; t < 1000u; ++t) {
    tick();
    TEST_ASSERT_TRUE(plant.omega_urad_s <= config.safety.omega_max_urad_s + 100000);
    TEST_ASSERT_TRUE(plant.omega_urad_s >= -config.safety.omega_max_urad_s - 100000);
  }
}

/* ... and where the band is wide open (a bench that disarms it), SCALE names the fault within 50 ticks. */
static void test_supervisor_ScaleStuckHighIsCaughtWithin50TicksWithoutTheBand(void) {
  config.safety.omega_max_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
  config.safety.omega_slack_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
  config.supervisor.omega_max_urad_s = 22000000;
  config.sensors.jump_max_urad = 1000000; /* 2,000 rad/s² puts the loop 22 mrad behind: beyond the default */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &config, &pour_weights_compiled));
  plant.gain = 10;
  const uint32_t t = ticks_until(POUR_FAULT_SCALE | POUR_FAULT_OVERSPEED, 200u);
  TEST_ASSERT_TRUE(t <= DETECT_TICKS_MAX);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_SCALE, out.faults);
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
      (void)sample_now();
      pour_control_step(&ctl, &in, &out);
      check_envelope();
      plant_step(out.power ? out.torque : 0);
    } else {
      tick();
    }
  }
  TEST_ASSERT_EQUAL_HEX16(0, out.faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

/* Held readings with a fast, real flow (2 % of the liquid a tick, 24 % in each 80 Hz step) are no fault ... */
static void test_supervisor_HeldScaleStepsOfARealFlowAreNoFault(void) {
  plant.flow_g_per_tick = 200;
  run_ticks(48u);
  TEST_ASSERT_EQUAL_HEX16(0, out.faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
}

/* ... a reading that jumps by the whole liquid in one update (a tare lost, a cell unplugged) is. */
static void test_supervisor_VolumeJumpIsCaughtAtTheNextScaleUpdate(void) {
  run_ticks(30u);
  plant.m_rot_g -= LIQUID_G;
  const uint32_t t = ticks_until(POUR_FAULT_VOLUME, 50u);
  TEST_ASSERT_TRUE(t <= SCALE_PERIOD_TICKS);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
}

static void test_supervisor_OverspeedStopsActivelyThenBrakes(void) {
  run_ticks(20u);
  plant.omega_urad_s = 6000000; /* a runaway: 6 rad/s, beyond what the envelope lets the motor give */
  const uint32_t t = ticks_until(POUR_FAULT_OVERSPEED, 10u);
  TEST_ASSERT_TRUE(t <= 3u); /* the estimate catches up with a step in speed within 3 ticks */
  /* The sensors and the motor are trusted: decelerate with power on, brake off ... */
  const q15_t before = out.torque;
  tick();
  TEST_ASSERT_TRUE(out.power);
  TEST_ASSERT_FALSE(out.brake);
  TEST_ASSERT_TRUE(out.torque < before);
  /* ... back toward upright at a bounded speed, then brake once at rest. */
  int32_t peak_back = 0;
  for (uint32_t k = 0; k < 6000u && out.power; ++k) {
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

/* The bucket coasts backwards (the motor disconnected) past θmin - margin: POSITION the tick it is seen. */
static void test_supervisor_PositionPastTheMarginIsCaught(void) {
  const int32_t low = config.safety.theta_min_urad - config.supervisor.theta_margin_urad;
  plant.theta_urad = low + 5000;
  plant.omega_urad_s = -1000000;
  plant.gain = 0;
  uint32_t crossed = 0u;
  for (uint32_t t = 1; t <= 20u && (out.faults & POUR_FAULT_POSITION) == 0u; ++t) {
    tick();
    if (crossed == 0u && plant.theta_urad < low) {
      crossed = t;
    }
  }
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_POSITION, out.faults);
  TEST_ASSERT_TRUE(crossed > 0u);
}

static void test_supervisor_ClearAfterAStopRampsThroughSlewAndRunsAgain(void) {
  plant.motor_sign = -1;
  (void)ticks_until(POUR_FAULT_TORQUE_SIGN, 200u);
  plant.motor_sign = 1;
  pour_control_input_t in = {0};
  in.clear_faults = true;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  last_torque = out.torque;
  run_ticks(50u); /* tick() checks the envelope on every step; the bucket, still moving back, turns round */
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
  in.sensors_fresh = true;
  for (uint32_t t = 0; t < 40000u; ++t) {
    in.sensors = sample_now();
    pour_control_step(&ctl, &in, &out);
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  in.clear_faults = true;
  in.sensors = sample_now();
  pour_control_step(&ctl, &in, &out);
  in.clear_faults = false;
  in.sensors = sample_now();
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
  RUN_TEST(test_supervisor_ScaleStuckHighIsContainedByTheSpeedBand);
  RUN_TEST(test_supervisor_ScaleStuckHighIsCaughtWithin50TicksWithoutTheBand);
  RUN_TEST(test_supervisor_FrozenSenderIsStaleAndSeqWithinTheTimeout);
  RUN_TEST(test_supervisor_LostStatesAreNotAFault);
  RUN_TEST(test_supervisor_HeldScaleStepsOfARealFlowAreNoFault);
  RUN_TEST(test_supervisor_VolumeJumpIsCaughtAtTheNextScaleUpdate);
  RUN_TEST(test_supervisor_OverspeedStopsActivelyThenBrakes);
  RUN_TEST(test_supervisor_PositionPastTheMarginIsCaught);
  RUN_TEST(test_supervisor_ClearAfterAStopRampsThroughSlewAndRunsAgain);
  RUN_TEST(test_supervisor_LongFaultThenClearStillResumes);
  RUN_TEST(test_supervisor_init_RefusesBadConfig);
  return UNITY_END();
}
