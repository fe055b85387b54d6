/* SPDX-License-Identifier: MIT */
/* CAN node: frames -> control input, watchdog, heartbeat schedule, dropped-frame accounting; and the node
 * with the real control core behind it, as both ports run them (one sensor sample for node and core). */
#include <string.h>

#include "pour/can_node.h"
#include "pour/params.h"
#include "pour/drive_faults.h"
#include "pour/weights_compiled.h"
#include "unity.h"

static pour_can_node_t node;
static pour_can_node_config_t cfg;
static pour_control_t ctl;
static pour_control_config_t ccfg;

void setUp(void) {
  cfg = pour_can_node_default_config();
  cfg.node_id = 3;
  cfg.watchdog_ms = 5;
  cfg.heartbeat_period_ms = 4;
  cfg.identity.weights_hash = 0xabcdef01u;
  cfg.identity.tau_max_cnm = 2000u;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &cfg));
  ccfg = pour_control_default_config();
  ccfg.supervisor.checks = POUR_CHECK_ALL & ~(POUR_CHECK_ENCODER | POUR_CHECK_TORQUE_SIGN); /* scripted samples */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &ccfg, &pour_weights_compiled));
}

void tearDown(void) {}

/* One Sensors frame: the encoder at count, 10 kg of liquid in the rotating bucket, 300 g in the target. */
static void send_sample(uint32_t seq, uint32_t encoder) {
  const pour_can_sensors_t m = {.seq_low = (uint8_t)(seq & 0xFFu), .encoder = encoder, .scale_rotating_g = 10000,
                                .scale_target_g = 300};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(cfg.node_id, &m, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
}

/* One tick with a stand-in controller output that holds the given torque in RUN. */
static uint8_t tick(q15_t torque, pour_control_input_t *in, pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX]) {
  pour_can_node_begin_tick(&node, in);
  pour_control_output_t out;
  memset(&out, 0, sizeof out);
  out.torque = in->estop ? 0 : torque;
  out.mode = (uint8_t)(in->estop ? POUR_MODE_ESTOP : POUR_MODE_RUN);
  out.action = 4;
  return pour_can_node_end_tick(&node, &out, 9, tx);
}

/* One tick in the given mode after a CalibrationStart: the CalibrationResult it produced, decoded. */
static pour_can_calibration_result_t calibration_answer(uint8_t mode) {
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(cfg.node_id, POUR_CAN_CMD_CALIBRATION_START, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  pour_control_input_t in;
  pour_can_node_begin_tick(&node, &in);
  pour_control_output_t out;
  memset(&out, 0, sizeof out);
  out.mode = mode;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  const uint8_t n = pour_can_node_end_tick(&node, &out, 0, tx);
  pour_can_calibration_result_t r;
  memset(&r, 0xFF, sizeof r);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&tx[n - 1u], &r));
  /* one answer per request */
  pour_can_node_begin_tick(&node, &in);
  const uint8_t next = pour_can_node_end_tick(&node, &out, 0, tx);
  for (uint8_t i = 0; i < next; ++i) {
    TEST_ASSERT_NOT_EQUAL((int)pour_can_id(cfg.node_id, POUR_CAN_CMD_CALIBRATION_RESULT), (int)tx[i].id);
  }
  return r;
}

static void test_can_node_CalibrationStartIsRefusedInRunAndEstopWithItsReason(void) {
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_RUNNING, calibration_answer((uint8_t)POUR_MODE_RUN).status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_ESTOP, calibration_answer((uint8_t)POUR_MODE_ESTOP).status);
  const pour_can_calibration_result_t idle = calibration_answer((uint8_t)POUR_MODE_IDLE);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_UNAVAILABLE, idle.status); /* no port answer set: it cannot measure */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_EMPTY, idle.stored);
  const pour_can_calibration_result_t stored = {.status = POUR_CAN_CAL_UNAVAILABLE, .stored = POUR_CAN_CAL_OK,
                                                .encoder_reversed = 0u, .pole_pairs = 8u, .resistance_mohm = 304u,
                                                .inductance_uh = 231u, .electrical_offset = 17u};
  pour_can_node_set_calibration(&node, &stored);
  const pour_can_calibration_result_t fault = calibration_answer((uint8_t)POUR_MODE_FAULT);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, fault.stored); /* the stored calibration, read back */
  TEST_ASSERT_EQUAL_UINT8(8u, fault.pole_pairs);
  TEST_ASSERT_EQUAL_UINT16(304u, fault.resistance_mohm);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_RUNNING, calibration_answer((uint8_t)POUR_MODE_RUN).status);
}

static void test_can_node_CalibrationStartGoesToAPortThatMeasuresAndItsOutcomeFollows(void) {
  cfg.can_calibrate = true;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &cfg));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_RUNNING, calibration_answer((uint8_t)POUR_MODE_RUN).status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_ESTOP, calibration_answer((uint8_t)POUR_MODE_ESTOP).status);
  TEST_ASSERT_FALSE(pour_can_node_take_calibration_start(&node)); /* refused: nothing for the port */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, calibration_answer((uint8_t)POUR_MODE_IDLE).status);
  TEST_ASSERT_TRUE(pour_can_node_take_calibration_start(&node));
  TEST_ASSERT_FALSE(pour_can_node_take_calibration_start(&node)); /* once */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, calibration_answer((uint8_t)POUR_MODE_FAULT).status);
  TEST_ASSERT_TRUE(pour_can_node_take_calibration_start(&node));
  /* the outcome, unasked, once */
  const pour_can_calibration_result_t done = {.status = POUR_CAN_CAL_NO_ENCODER, .stored = POUR_CAN_CAL_EMPTY};
  pour_can_node_report_calibration(&node, &done);
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  int seen = 0;
  for (int t = 0; t < 3; ++t) {
    const uint8_t n = tick(0, &in, tx);
    for (uint8_t i = 0; i < n; ++i) {
      pour_can_calibration_result_t r;
      if (tx[i].id != pour_can_id(cfg.node_id, POUR_CAN_CMD_CALIBRATION_RESULT)) continue;
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&tx[i], &r));
      TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_NO_ENCODER, r.status);
      ++seen;
    }
  }
  TEST_ASSERT_EQUAL_INT(1, seen);
}

/* The port's interlock: a refusal is answered with its reason and never handed to the port; RUN and the
 * e-stop still come first; MEASURING again hands the next one over. */
static void test_can_node_CalibrationStartFollowsThePortsGate(void) {
  cfg.can_calibrate = true;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &cfg));
  pour_can_node_gate_calibration(&node, POUR_CAN_CAL_REFUSED_NOT_EMPTY);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_NOT_EMPTY, calibration_answer((uint8_t)POUR_MODE_IDLE).status);
  TEST_ASSERT_FALSE(pour_can_node_take_calibration_start(&node));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_RUNNING, calibration_answer((uint8_t)POUR_MODE_RUN).status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_REFUSED_ESTOP, calibration_answer((uint8_t)POUR_MODE_ESTOP).status);
  pour_can_node_gate_calibration(&node, POUR_CAN_CAL_MEASURING);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_MEASURING, calibration_answer((uint8_t)POUR_MODE_IDLE).status);
  TEST_ASSERT_TRUE(pour_can_node_take_calibration_start(&node));
}

static void test_can_node_init_RejectsBadConfig(void) {
  pour_can_node_config_t bad = cfg;
  bad.node_id = 64;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(&node, &bad));
  bad = cfg;
  bad.watchdog_ms = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(&node, &bad));
  bad = cfg;
  bad.heartbeat_period_ms = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(&node, &bad));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_init(NULL, &cfg));
}

static void test_can_node_SensorsFrameBecomesOneFreshRawSample(void) {
  send_sample(0x34, 0x1FFFFu);
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  tick(100, &in, tx);
  TEST_ASSERT_TRUE(in.sensors_fresh);
  TEST_ASSERT_EQUAL_UINT32(0x34, in.sensors.seq);
  TEST_ASSERT_EQUAL_UINT32(0x1FFFFu, in.sensors.encoder); /* as read: the core's estimator converts it */
  TEST_ASSERT_EQUAL_INT32(10000, in.sensors.scale_rotating_g);
  TEST_ASSERT_EQUAL_INT32(300, in.sensors.scale_target_g);
  tick(100, &in, tx);
  TEST_ASSERT_FALSE(in.sensors_fresh);
}

static void test_can_node_TorqueFrameEchoesSeqEveryTick(void) {
  send_sample(77, 0);
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  uint8_t n = tick(-1234, &in, tx);
  TEST_ASSERT_EQUAL_UINT8(3, n); /* torque + first heartbeat and identity */
  pour_can_torque_t t;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &t));
  TEST_ASSERT_EQUAL_HEX16(pour_can_id(3, POUR_CAN_CMD_TORQUE), tx[0].id);
  TEST_ASSERT_EQUAL_UINT16(77, t.seq);
  TEST_ASSERT_EQUAL_INT16(-1234, t.torque);
  TEST_ASSERT_EQUAL_UINT8(4, t.action);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, t.mode);
}

static void test_can_node_HeartbeatAtConfiguredPeriod(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  unsigned heartbeats = 0;
  uint8_t last_counter = 0;
  for (unsigned t = 0; t < 12; ++t) {
    send_sample(t, 0);
    uint8_t n = tick(0, &in, tx);
    if (n == 3) {
      pour_can_heartbeat_t hb;
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[1], &hb));
      TEST_ASSERT_EQUAL_UINT(0, t % 4u);
      TEST_ASSERT_EQUAL_UINT16(9, hb.overruns);
      pour_can_identity_t id;
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_identity(&tx[2], &id));
      TEST_ASSERT_EQUAL_HEX32(0xabcdef01u, id.weights_hash);
      TEST_ASSERT_EQUAL_UINT16(2000u, id.tau_max_cnm);
      TEST_ASSERT_EQUAL_UINT8(POUR_FIRMWARE_VERSION, id.fw_version);
      last_counter = hb.counter;
      ++heartbeats;
    } else {
      TEST_ASSERT_EQUAL_UINT8(1, n);
    }
  }
  TEST_ASSERT_EQUAL_UINT(3, heartbeats);
  TEST_ASSERT_EQUAL_UINT8(2, last_counter);
}

static void test_can_node_DriveTelemetryFollowsEveryHeartbeatOnceSet(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  TEST_ASSERT_EQUAL_UINT8(3, tick(0, &in, tx)); /* no drive of its own: torque, heartbeat, identity */
  const pour_can_drive_telemetry_t d = {-1234, 5678, 24000u,
                                        POUR_DRIVE_FAULT_HW_OVERCURRENT | POUR_DRIVE_FAULT_OVERTEMP, 2u};
  pour_can_node_set_drive(&node, &d);
  unsigned telemetry = 0;
  for (unsigned t = 1; t < 12; ++t) {
    const uint8_t n = tick(0, &in, tx);
    if (t % 4u == 0u) {
      TEST_ASSERT_EQUAL_UINT8(4, n);
      pour_can_drive_telemetry_t back;
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_drive_telemetry(&tx[3], &back));
      TEST_ASSERT_EQUAL_INT16(-1234, back.id_2ma);
      TEST_ASSERT_EQUAL_INT16(5678, back.iq_2ma);
      TEST_ASSERT_EQUAL_UINT16(24000u, back.vbus_mv);
      TEST_ASSERT_EQUAL_HEX16(d.drive_faults, back.drive_faults);
      TEST_ASSERT_EQUAL_UINT8(2u, back.crystal_4mhz);
      ++telemetry;
    } else {
      TEST_ASSERT_EQUAL_UINT8(1, n);
    }
  }
  TEST_ASSERT_EQUAL_UINT(2, telemetry);
}

static void test_can_node_DriveFaultFaultsTheCoreAndTheHeartbeatNamesIt(void) {
  pour_control_input_t in;
  pour_can_node_begin_tick(&node, &in);
  TEST_ASSERT_EQUAL_HEX16(0u, in.drive_faults); /* the bus carries no drive */
  TEST_ASSERT_TRUE(in.drive_trusted);
  in.drive_faults = POUR_DRIVE_FAULT_OVERTEMP; /* the port's drive, as board_drive fills it in */
  pour_control_output_t out;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  TEST_ASSERT_TRUE(out.brake);
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  TEST_ASSERT_EQUAL_UINT8(3, pour_can_node_end_tick(&node, &out, 0, tx));
  pour_can_heartbeat_t hb;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[1], &hb));
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_DRIVE, hb.faults);
  TEST_ASSERT_EQUAL_STRING("DRIVE", pour_fault_name(POUR_FAULT_DRIVE));
}

static void test_can_node_SilenceTripsWatchdogAfterTimeout(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  for (unsigned t = 0; t < 20; ++t) { /* not armed before the first valid frame */
    tick(1000, &in, tx);
    TEST_ASSERT_FALSE(in.link_fault);
  }
  send_sample(1, 0);
  for (unsigned t = 0; t < 6; ++t) {
    tick(1000, &in, tx);
    TEST_ASSERT_FALSE(in.link_fault);
  }
  tick(1000, &in, tx); /* 6 ms without a valid frame > 5 ms */
  TEST_ASSERT_TRUE(in.link_fault);
  send_sample(2, 0); /* a valid frame ends the trip; the core keeps it latched until a clear */
  tick(1000, &in, tx);
  TEST_ASSERT_FALSE(in.link_fault);
}

/* The core behind the node, one tick: what goes on the bus. */
static pour_can_torque_t core_tick(pour_control_output_t *out) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  pour_can_node_begin_tick(&node, &in);
  pour_control_step(&ctl, &in, out);
  TEST_ASSERT_TRUE(pour_can_node_end_tick(&node, out, 0, tx) >= 1u);
  pour_can_torque_t tq;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
  TEST_ASSERT_EQUAL_INT16(out->torque, tq.torque); /* the bus carries the core's output, nothing else */
  return tq;
}

static void receive_command(uint8_t cmd) {
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_command(cfg.node_id, cmd, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
}

/* The heartbeat's Held of a core booted held (as the board's main.c does): the stream of samples starts no
 * run, the heartbeat says Held in IDLE, until the host's Reset frame arms the run; a Stop holds it again. */
static uint8_t held_bit(void) {
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  pour_control_output_t out;
  memset(&out, 0, sizeof out);
  out.mode = (uint8_t)ctl.mode;
  pour_can_node_set_held(&node, pour_control_held(&ctl));
  TEST_ASSERT_EQUAL_UINT8(2, pour_can_node_status_frames(&node, &out, 0, tx));
  pour_can_heartbeat_t hb;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[0], &hb));
  TEST_ASSERT_EQUAL_UINT8(hb.held, (uint8_t)(tx[0].data[2] >> 7)); /* bit 23 (can/pour.dbc, Held) */
  return hb.held;
}

static void test_can_node_HeldAtBootUntilAResetFrameAndAfterAStop(void) {
  pour_control_hold(&ctl);
  pour_control_output_t out;
  uint32_t seq = 1u;
  for (int i = 0; i < 50; ++i) {
    send_sample(seq++, 100u);
    core_tick(&out);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
    TEST_ASSERT_TRUE(out.brake);
  }
  TEST_ASSERT_EQUAL_UINT8(1u, held_bit());
  receive_command(POUR_CAN_CMD_RESET);
  send_sample(seq++, 100u);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT8(0u, held_bit());
  receive_command(POUR_CAN_CMD_STOP);
  for (int i = 0; i < 50; ++i) {
    send_sample(seq++, 100u);
    core_tick(&out);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  }
  TEST_ASSERT_EQUAL_UINT8(1u, held_bit());
}

/* A bench with no host stream: commands alone never arm the watchdog, so the e-stop, its release and the clear
 * leave an idle node IDLE (docs/bringup.md step 5), however long the bus then stays silent; the first sample
 * arms it, and then silence trips it. */
static void test_can_node_CommandsAloneNeverArmTheWatchdog(void) {
  pour_control_output_t out;
  pour_can_frame_t f;
  static const struct { uint8_t assert_estop; uint8_t mode; } steps[] = {
      {1u, POUR_MODE_ESTOP}, {0u, POUR_MODE_FAULT}};
  for (unsigned i = 0; i < 2u; ++i) {
    const pour_can_estop_t e = {.assert_estop = steps[i].assert_estop};
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
    TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
    for (unsigned t = 0; t < 20u; ++t) {
      TEST_ASSERT_TRUE(pour_can_node_watchdog(&node, 1u) == false);
      core_tick(&out);
    }
    TEST_ASSERT_EQUAL_UINT8(steps[i].mode, out.mode);
  }
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  for (unsigned t = 0; t < 500u; ++t) {
    TEST_ASSERT_FALSE(pour_can_node_watchdog(&node, 1u));
    core_tick(&out);
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_HEX16(0u, out.faults);
  TEST_ASSERT_TRUE(out.brake);
  send_sample(1, 0);
  for (unsigned t = 0; t <= cfg.watchdog_ms; ++t) {
    (void)pour_can_node_watchdog(&node, 1u);
  }
  core_tick(&out);
  TEST_ASSERT_EQUAL_HEX16(POUR_FAULT_LINK, out.faults & POUR_FAULT_LINK);
}

/* The Linux port's watchdog runs on the wall clock: it can trip while samples still arrive (a slow guest in
 * lockstep). Then the core itself goes to FAULT, and ClearErrors lets the torque back only through the slew
 * limit (it used to jump from 0 to the core's hidden command, 32767, in one tick). */
static void test_can_node_WatchdogFaultsTheCoreAndClearRampsThroughSlew(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  q15_t peak = 0;
  for (unsigned t = 0; t < 40u; ++t) {
    send_sample(seq++, 0);
    peak = core_tick(&out).torque > peak ? out.torque : peak;
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_TRUE(peak > ccfg.safety.slew_per_tick); /* the policy did ramp up: a jump would show */
  TEST_ASSERT_TRUE(pour_can_node_watchdog(&node, 60));
  for (unsigned t = 0; t < 30u; ++t) { /* the core's command would keep ramping behind a bus override */
    pour_can_torque_t tq = core_tick(&out);
    TEST_ASSERT_EQUAL_INT16(0, tq.torque);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, tq.mode);
    TEST_ASSERT_BITS_HIGH(POUR_FAULT_LINK, out.faults);
    (void)pour_can_node_watchdog(&node, 60);
  }
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  q15_t last = 0;
  for (unsigned t = 0; t < 40u; ++t) {
    send_sample(seq++, 0);
    pour_can_torque_t tq = core_tick(&out);
    const int32_t step = (int32_t)tq.torque - last;
    TEST_ASSERT_TRUE(step <= ccfg.safety.slew_per_tick && step >= -ccfg.safety.slew_per_tick);
    last = tq.torque;
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_HEX16(0, out.faults);
}

/* E-stop wins over every other output: a tripped watchdog with a non-zero safe torque included. */
static void test_can_node_EstopWinsOverWatchdogSafeTorque(void) {
  ccfg.safe_torque = 3000;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &ccfg, &pour_weights_compiled));
  pour_control_output_t out;
  send_sample(1, 0);
  core_tick(&out);
  pour_can_frame_t f;
  const pour_can_estop_t e = {.assert_estop = 1};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  TEST_ASSERT_TRUE(pour_can_node_watchdog(&node, 60));
  for (unsigned t = 0; t < 5u; ++t) {
    pour_can_torque_t tq = core_tick(&out);
    TEST_ASSERT_EQUAL_INT16(0, tq.torque);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, tq.mode);
  }
}

/* The frame's seq wraps every 256 samples (256 ms at 1 kHz): a wrap is the next sample, not a new run, and
 * the 32-bit count the core sees (its estimator's gap, the torque frame's 16-bit echo) runs on through it;
 * lost frames advance it by the forward distance. */
static void test_can_node_SeqWrapIsTheNextSampleNotANewRun(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  for (uint32_t k = 0; k < 70000u; k += (k % 1000u == 999u) ? 3u : 1u) { /* now and then 2 frames lost */
    send_sample(k, 0);
    pour_can_node_begin_tick(&node, &in);
    TEST_ASSERT_TRUE(in.sensors_fresh);
    TEST_ASSERT_EQUAL_UINT32(k, in.sensors.seq);
    TEST_ASSERT_FALSE(in.reset);
  }
  (void)tx;
  /* A Reset asks the core for a new run but leaves the count alone: the new run's first frame (seq 0) is the
   * next sample by its forward distance, which a core that accepted the Reset takes whatever its value. */
  const uint32_t last = in.sensors.seq;
  receive_command(POUR_CAN_CMD_RESET);
  send_sample(0, 0);
  pour_can_node_begin_tick(&node, &in);
  TEST_ASSERT_TRUE(in.reset);
  TEST_ASSERT_EQUAL_UINT32(last + ((0u - last) & 0xFFu), in.sensors.seq);
}

/* A Sensors frame may carry what no sensor of the rig can read (a count past the encoder's 2^17, a scale past
 * its limits): the node passes it on as it came, and the core refuses it as BAD_INPUT, a latched fault the
 * heartbeat carries; the bus never sees torque from it. */
static void test_can_node_ImpossibleSampleLatchesBadInputInTheCore(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  for (unsigned t = 0; t < 20u; ++t) {
    send_sample(seq++, 0);
    core_tick(&out);
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  send_sample(seq++, 1u << 17); /* the default encoder has 17 bits: counts 0 .. 2^17 - 1 */
  pour_can_torque_t tq = core_tick(&out);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_BAD_INPUT, out.faults);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, tq.mode);
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  TEST_ASSERT_EQUAL_UINT8(2, pour_can_node_status_frames(&node, &out, 0, tx));
  pour_can_heartbeat_t hb;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[0], &hb));
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_BAD_INPUT, hb.faults);

  /* The same for a scale reading past the load cell's limit (30 kg by default), on a fresh core. */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &ccfg, &pour_weights_compiled));
  send_sample(seq++, 0);
  core_tick(&out);
  const pour_can_sensors_t heavy = {.seq_low = (uint8_t)(seq & 0xFFu), .encoder = 0, .scale_rotating_g = 10000,
                                    .scale_target_g = (int16_t)(ccfg.sensors.scale_max_g + 1)};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(cfg.node_id, &heavy, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  core_tick(&out);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_BAD_INPUT, out.faults);
}

/* A reset is refused while the core runs; Stop first ends the run. */
static void test_can_node_ResetIsRefusedInRunAndAcceptedAfterStop(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  for (unsigned t = 0; t < 30u; ++t) {
    send_sample(seq++, 0);
    core_tick(&out);
  }
  const q15_t running = out.torque;
  receive_command(POUR_CAN_CMD_RESET);
  send_sample(seq++, 0);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT32(1, ctl.refused);
  TEST_ASSERT_TRUE(out.torque >= running - ccfg.safety.slew_per_tick); /* no drop to a fresh start */
  receive_command(POUR_CAN_CMD_STOP);
  receive_command(POUR_CAN_CMD_RESET);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  TEST_ASSERT_EQUAL_UINT32(1, ctl.refused);
}

static void test_can_node_EstopLevelReachesTheNextTick(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  send_sample(1, 0);
  tick(5000, &in, tx);
  pour_can_frame_t f;
  pour_can_estop_t e = {.assert_estop = 1};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  tick(5000, &in, tx);
  TEST_ASSERT_TRUE(in.estop);
  pour_can_torque_t tq;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_torque(&tx[0], &tq));
  TEST_ASSERT_EQUAL_INT16(0, tq.torque);
  tick(5000, &in, tx);
  TEST_ASSERT_TRUE(in.estop); /* a level, not a pulse */
  e.assert_estop = 0;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  tick(5000, &in, tx);
  TEST_ASSERT_FALSE(in.estop);
}

static void test_can_node_MalformedFramesAreDroppedAndCounted(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  send_sample(1, 42);
  tick(0, &in, tx);
  pour_can_frame_t f;
  /* wrong DLC */
  const pour_can_sensors_t m = {.seq_low = 2, .encoder = 999, .scale_rotating_g = 1, .scale_target_g = 1};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(cfg.node_id, &m, &f));
  f.dlc = 6;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_node_receive(&node, &f));
  /* unknown cmd, and a cmd only the controller sends */
  f.id = pour_can_id(cfg.node_id, 0x1F);
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  pour_can_torque_t t = {0};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_torque(cfg.node_id, &t, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  /* a scale reading of -32768 g: the load cell amplifier's overload code */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(cfg.node_id, &m, &f));
  f.data[6] = 0x00;
  f.data[7] = 0x80;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_node_receive(&node, &f));
  /* the retired StateB id of protocol 2 (0x11) is no command any more */
  f.id = pour_can_id(cfg.node_id, 0x11);
  f.dlc = 8;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_ID, pour_can_node_receive(&node, &f));
  /* another node's sample: ignored, not an error */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_sensors(7, &m, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OTHER_NODE, pour_can_node_receive(&node, &f));

  TEST_ASSERT_EQUAL_UINT32(1, node.counters.bad_dlc);
  TEST_ASSERT_EQUAL_UINT32(3, node.counters.bad_id);
  TEST_ASSERT_EQUAL_UINT32(1, node.counters.out_of_range);
  TEST_ASSERT_EQUAL_UINT32(1, node.counters.other_node);
  TEST_ASSERT_EQUAL_UINT32(5, pour_can_node_dropped(&node));
  tick(0, &in, tx);
  TEST_ASSERT_FALSE(in.sensors_fresh);
  TEST_ASSERT_EQUAL_UINT32(42, in.sensors.encoder); /* nothing of the bad frames got through */
  TEST_ASSERT_EQUAL_INT32(10000, in.sensors.scale_rotating_g);
}

static void receive_estop(bool asserted) {
  pour_can_frame_t f;
  const pour_can_estop_t e = {.assert_estop = asserted ? 1u : 0u};
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_estop(cfg.node_id, &e, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
}

/* Runs the core on samples for n ticks; returns the last output. */
static void run_ticks(unsigned n, uint32_t *seq, pour_control_output_t *out) {
  for (unsigned t = 0; t < n; ++t) {
    send_sample((*seq)++, 0);
    core_tick(out);
  }
}

/* A CalibrationRead with the core behind the node: the one CalibrationResult of the next tick, decoded; the
 * core's mode and refusal count as they were, and nothing handed to the port to measure. */
static pour_can_calibration_result_t read_calibration(pour_control_output_t *out) {
  const uint8_t mode = out->mode;
  const uint32_t refused = ctl.refused;
  receive_command(POUR_CAN_CMD_CALIBRATION_READ);
  /* no sample with it: in IDLE one would start a run */
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  pour_can_node_begin_tick(&node, &in);
  pour_control_step(&ctl, &in, out);
  const uint8_t n = pour_can_node_end_tick(&node, out, 0, tx);
  pour_can_calibration_result_t r;
  memset(&r, 0xFF, sizeof r);
  int answers = 0;
  for (uint8_t i = 0; i < n; ++i) {
    if (tx[i].id == pour_can_id(cfg.node_id, POUR_CAN_CMD_CALIBRATION_RESULT)) {
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&tx[i], &r));
      ++answers;
    }
  }
  TEST_ASSERT_EQUAL_INT(1, answers);
  TEST_ASSERT_EQUAL_UINT8(mode, out->mode);
  TEST_ASSERT_EQUAL_UINT32(refused, ctl.refused);
  TEST_ASSERT_FALSE(pour_can_node_take_calibration_start(&node));
  return r;
}

static void assert_stored_block(const pour_can_calibration_result_t *r) {
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_STORED, r->status);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_OK, r->stored);
  TEST_ASSERT_EQUAL_UINT8(1u, r->encoder_reversed);
  TEST_ASSERT_EQUAL_UINT8(8u, r->pole_pairs);
  TEST_ASSERT_EQUAL_UINT16(304u, r->resistance_mohm);
  TEST_ASSERT_EQUAL_UINT16(231u, r->inductance_uh);
  TEST_ASSERT_EQUAL_UINT8(17u, r->electrical_offset);
}

/* The read-only query: answered in RUN, ESTOP, FAULT and IDLE with the stored block, status STORED, and
 * never a start, a refusal or a change of mode. */
static void test_can_node_CalibrationReadAnswersTheStoredBlockInEveryModeAndChangesNothing(void) {
  cfg.can_calibrate = true;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_init(&node, &cfg));
  const pour_can_calibration_result_t stored = {.status = POUR_CAN_CAL_UNAVAILABLE, .stored = POUR_CAN_CAL_OK,
                                                .encoder_reversed = 1u, .pole_pairs = 8u, .resistance_mohm = 304u,
                                                .inductance_uh = 231u, .electrical_offset = 17u};
  pour_can_node_set_calibration(&node, &stored);
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(30u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  pour_can_calibration_result_t r = read_calibration(&out);
  assert_stored_block(&r);
  receive_estop(true);
  run_ticks(5u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  r = read_calibration(&out);
  assert_stored_block(&r);
  receive_estop(false);
  run_ticks(5u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out.mode);
  r = read_calibration(&out);
  assert_stored_block(&r);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  run_ticks(5u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  receive_command(POUR_CAN_CMD_STOP);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_IDLE, out.mode);
  r = read_calibration(&out);
  assert_stored_block(&r);
  TEST_ASSERT_EQUAL_UINT32(0u, ctl.refused);
}

/* A controller without a calibration of its own says so; a read waits behind a start's answer (one
 * CalibrationResult a tick) and does not feed the command watchdog. */
static void test_can_node_CalibrationReadWithoutAStoreIsUnavailableAndWaitsItsTurn(void) {
  pour_control_input_t in;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  receive_command(POUR_CAN_CMD_CALIBRATION_READ);
  receive_command(POUR_CAN_CMD_CALIBRATION_START);
  uint8_t statuses[3] = {0xFFu, 0xFFu, 0xFFu};
  for (int t = 0; t < 3; ++t) {
    pour_can_node_begin_tick(&node, &in);
    pour_control_output_t out;
    memset(&out, 0, sizeof out);
    out.mode = (uint8_t)POUR_MODE_IDLE;
    const uint8_t n = pour_can_node_end_tick(&node, &out, 0, tx);
    for (uint8_t i = 0; i < n; ++i) {
      pour_can_calibration_result_t r;
      if (tx[i].id != pour_can_id(cfg.node_id, POUR_CAN_CMD_CALIBRATION_RESULT)) continue;
      TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_calibration_result(&tx[i], &r));
      TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_EMPTY, r.stored);
      statuses[t] = r.status;
    }
  }
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_UNAVAILABLE, statuses[0]); /* the start's answer: it cannot measure */
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CAL_UNAVAILABLE, statuses[1]); /* the read's: nothing of its own stored */
  TEST_ASSERT_EQUAL_UINT8(0xFFu, statuses[2]);                    /* one answer each */
  /* Only reads since: the watchdog is not fed by them and trips on the silence. */
  pour_can_node_init(&node, &cfg);
  send_sample(1, 0);
  for (unsigned t = 0; t <= cfg.watchdog_ms; ++t) {
    receive_command(POUR_CAN_CMD_CALIBRATION_READ);
    tick(0, &in, tx);
  }
  pour_can_node_begin_tick(&node, &in);
  TEST_ASSERT_TRUE(in.link_fault);
}

/* After a clear that did not count (dropped clears so far): FAULT, the e-stop fault latched, the brake on. */
static void assert_estop_still_latched(const pour_control_output_t *out, uint32_t dropped) {
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_FAULT, out->mode);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_ESTOP, out->faults);
  TEST_ASSERT_TRUE(out->brake);
  TEST_ASSERT_EQUAL_UINT32(dropped, node.commands.clears_dropped);
}

/* docs/safety.md, transitions: a ClearErrors that arrives while the e-stop is held is dropped where it arrives,
 * even when the release follows it before the next tick; the e-stop fault stays latched and no torque comes. */
static void test_can_node_ClearBeforeTheReleaseInOneTickIsDropped(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(30u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  receive_estop(true);
  run_ticks(5u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  receive_estop(false);
  run_ticks(50u, &seq, &out);
  assert_estop_still_latched(&out, 1u);
  /* The deliberate second step: a clear after the release counts. */
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  send_sample(seq++, 0);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT32(0u, out.faults);
}

/* The other order within one tick, release then clear, is the documented clear: it counts. An assert after a
 * clear in the same tick, or a pulse (assert, release, clear), drops the clear. */
static void test_can_node_ClearCountsOnlyAfterTheReleaseAndWhileReleased(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(10u, &seq, &out);
  receive_estop(true);
  run_ticks(3u, &seq, &out);
  receive_estop(false);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  receive_estop(true);
  run_ticks(3u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  receive_estop(false);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  receive_estop(true);
  receive_estop(false); /* a pulse after the clear: the assert is not lost, and it drops the clear */
  send_sample(seq++, 0);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  run_ticks(3u, &seq, &out);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_ESTOP, out.faults);
  TEST_ASSERT_EQUAL_UINT32(2u, node.commands.clears_dropped);
  receive_estop(false);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  send_sample(seq++, 0);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT32(0u, out.faults);
}

/* A ClearErrors every tick for a second while the e-stop is held clears nothing. */
static void test_can_node_ClearStormWhileEstopHeldClearsNothing(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(10u, &seq, &out);
  receive_estop(true);
  for (unsigned t = 0; t < 1000u; ++t) {
    receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
    send_sample(seq++, 0);
    core_tick(&out);
    TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
    TEST_ASSERT_EQUAL_INT16(0, out.torque);
  }
  receive_estop(false);
  run_ticks(20u, &seq, &out);
  TEST_ASSERT_BITS_HIGH(POUR_FAULT_ESTOP, out.faults);
  TEST_ASSERT_EQUAL_UINT32(1000u, node.commands.clears_dropped);
}

/* A Reset the core refuses in RUN changes nothing in the node either: the samples after it stay fresh and the
 * run goes on (the node used to restart its count, so the core took no sample as fresh and braked). */
static void test_can_node_RefusedResetInRunChangesNothing(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(300u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  const uint32_t seq_before = node.sensors.seq;
  receive_command(POUR_CAN_CMD_RESET);
  run_ticks(300u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT32(1u, ctl.refused);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT32(0u, out.faults);
  TEST_ASSERT_EQUAL_UINT32(seq_before + 300u, node.sensors.seq);
}

/* An ExperimentStart through node and core as the port runs them: the core's answer becomes a ParamAck with
 * its reason, and an accepted experiment drives the run's torque (Action = its phase). */
static pour_control_output_t experiment_out; /* the output of experiment_answer's tick */

static pour_can_param_ack_t experiment_answer(uint8_t kind, bool estop) {
  const pour_can_experiment_start_t m = {.kind = kind};
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_pack_experiment_start(cfg.node_id, &m, &f));
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_node_receive(&node, &f));
  uint8_t got = 0u;
  TEST_ASSERT_TRUE(pour_can_node_take_experiment(&node, &got));
  TEST_ASSERT_FALSE(pour_can_node_take_experiment(&node, &got)); /* taken once */
  TEST_ASSERT_EQUAL_UINT8(kind, got);
  pour_control_experiment(&ctl, got);
  pour_control_input_t in;
  pour_can_node_begin_tick(&node, &in);
  in.estop = estop;
  pour_control_output_t out;
  pour_control_step(&ctl, &in, &out);
  experiment_out = out;
  pour_can_frame_t ack;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_can_node_experiment_ack(&node, kind, pour_control_experiment_answer(&ctl), &ack));
  TEST_ASSERT_EQUAL_UINT16(pour_can_id(cfg.node_id, POUR_CAN_CMD_PARAM_ACK), ack.id);
  pour_can_param_ack_t a;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_param_ack(&ack, &a));
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_CMD_EXPERIMENT_START, a.request);
  TEST_ASSERT_EQUAL_UINT8(kind, a.param_id);
  return a;
}

/* The Refused count of the heartbeat the port sends after the tick of out. */
static uint8_t heartbeat_refused(const pour_control_output_t *out) {
  pour_can_frame_t tx[2];
  TEST_ASSERT_EQUAL_UINT8(2u, pour_can_node_status_frames(&node, out, 0u, tx));
  pour_can_heartbeat_t hb;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OK, pour_can_unpack_heartbeat(&tx[0], &hb));
  return hb.refused;
}

static void test_can_node_ExperimentStart_AnsweredWithTheCoresReason(void) {
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_ACK_REFUSED_ESTOP, experiment_answer(POUR_EXPERIMENT_IDENTIFY, true).result);
  TEST_ASSERT_EQUAL_UINT32(1u, ctl.refused);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_ACK_REFUSED_FAULT, experiment_answer(POUR_EXPERIMENT_IDENTIFY, false).result);
  TEST_ASSERT_EQUAL_UINT32(2u, ctl.refused);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_control_init(&ctl, &ccfg, &pour_weights_compiled));
  TEST_ASSERT_EQUAL_UINT8(POUR_PARAM_OK, experiment_answer(POUR_EXPERIMENT_IDENTIFY, false).result);
  TEST_ASSERT_EQUAL_UINT32(0u, ctl.refused); /* an accepted start is no refusal */
  send_sample(1, 0);
  pour_control_input_t in;
  pour_can_node_begin_tick(&node, &in);
  pour_control_output_t out;
  pour_control_step(&ctl, &in, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT8(POUR_EXPERIMENT_PHASE_RAMP, out.action);
  TEST_ASSERT_EQUAL_UINT8(POUR_CAN_ACK_REFUSED_RUNNING, experiment_answer(POUR_EXPERIMENT_TILT, false).result);
  /* Counted as the refused Stops, Resets and clears are: the heartbeat's Refused moves. */
  TEST_ASSERT_EQUAL_UINT32(1u, ctl.refused);
  TEST_ASSERT_EQUAL_UINT8(1u, heartbeat_refused(&experiment_out));
  /* Nothing asked, nothing to answer. */
  pour_can_frame_t ack;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_can_node_experiment_ack(&node, 1u, pour_control_experiment_answer(&ctl), &ack));
}

static void test_can_node_ExperimentStart_OfAnUnknownKindIsDropped(void) {
  pour_can_frame_t f = {.id = pour_can_id(cfg.node_id, POUR_CAN_CMD_EXPERIMENT_START), .dlc = 1u, .data = {3u}};
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_node_receive(&node, &f));
  f.data[0] = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_OUT_OF_RANGE, pour_can_node_receive(&node, &f));
  f.dlc = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_CAN_RX_BAD_DLC, pour_can_node_receive(&node, &f));
  uint8_t kind = 0u;
  TEST_ASSERT_FALSE(pour_can_node_take_experiment(&node, &kind));
  TEST_ASSERT_EQUAL_UINT32(3u, pour_can_node_dropped(&node));
}

/* The hardwired line, sampled before and after the tick's frames (main.c), joins the bus's e-stop: a clear that
 * arrives while the line is held is dropped even if the line is released by the second sample, a bus release
 * does not release a held line, and a clear with the line released at both samples counts. */
static void test_can_node_HardwiredLineHeldDropsAClearAndOutranksTheBus(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(10u, &seq, &out);
  pour_can_node_estop_line(&node, true);
  run_ticks(3u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  receive_estop(false); /* the bus says released; the line is still held */
  run_ticks(3u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, out.mode);
  TEST_ASSERT_EQUAL_INT16(0, out.torque);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS); /* arrives with the line held */
  pour_can_node_estop_line(&node, false);      /* the second sample of that tick finds it released */
  run_ticks(20u, &seq, &out);
  assert_estop_still_latched(&out, 1u);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  pour_can_node_estop_line(&node, false);
  send_sample(seq++, 0);
  core_tick(&out);
  TEST_ASSERT_EQUAL_UINT32(0u, out.faults);
}

/* The next heartbeat the node sends (the core behind it, samples flowing), decoded. */
static pour_can_heartbeat_t next_heartbeat(uint32_t *seq) {
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  for (unsigned t = 0; t <= cfg.heartbeat_period_ms; ++t) {
    send_sample((*seq)++, 0);
    pour_control_input_t in;
    pour_control_output_t out;
    pour_can_node_begin_tick(&node, &in);
    pour_control_step(&ctl, &in, &out);
    const uint8_t n = pour_can_node_end_tick(&node, &out, 0, tx);
    for (uint8_t i = 0; i < n; ++i) {
      pour_can_heartbeat_t hb;
      if (pour_can_unpack_heartbeat(&tx[i], &hb) == POUR_CAN_RX_OK) {
        return hb;
      }
    }
  }
  TEST_FAIL_MESSAGE("no heartbeat within its period");
  pour_can_heartbeat_t none = {0};
  return none;
}

/* The heartbeat's Refused counts every command that changed nothing: a Reset the core refuses in RUN, a Stop
 * outside RUN, a clear dropped with the e-stop held; mod 16. */
static void test_can_node_HeartbeatCountsRefusedCommands(void) {
  pour_control_output_t out;
  uint32_t seq = 0;
  run_ticks(20u, &seq, &out);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_RUN, out.mode);
  TEST_ASSERT_EQUAL_UINT8(0u, next_heartbeat(&seq).refused);
  receive_command(POUR_CAN_CMD_RESET);
  TEST_ASSERT_EQUAL_UINT8(1u, next_heartbeat(&seq).refused);
  receive_estop(true);
  receive_command(POUR_CAN_CMD_CLEAR_ERRORS);
  pour_can_heartbeat_t hb = next_heartbeat(&seq);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, hb.mode);
  TEST_ASSERT_EQUAL_UINT8(2u, hb.refused);
  for (unsigned k = 0; k < 15u; ++k) {
    receive_command(POUR_CAN_CMD_STOP);
    run_ticks(1u, &seq, &out);
  }
  hb = next_heartbeat(&seq);
  TEST_ASSERT_EQUAL_UINT8(POUR_MODE_ESTOP, hb.mode); /* the mode is not disturbed by the count beside it */
  TEST_ASSERT_EQUAL_UINT8((2u + 15u) % 16u, hb.refused);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_can_node_init_RejectsBadConfig);
  RUN_TEST(test_can_node_CalibrationStartIsRefusedInRunAndEstopWithItsReason);
  RUN_TEST(test_can_node_CalibrationStartGoesToAPortThatMeasuresAndItsOutcomeFollows);
  RUN_TEST(test_can_node_CalibrationStartFollowsThePortsGate);
  RUN_TEST(test_can_node_CalibrationReadAnswersTheStoredBlockInEveryModeAndChangesNothing);
  RUN_TEST(test_can_node_CalibrationReadWithoutAStoreIsUnavailableAndWaitsItsTurn);
  RUN_TEST(test_can_node_SensorsFrameBecomesOneFreshRawSample);
  RUN_TEST(test_can_node_TorqueFrameEchoesSeqEveryTick);
  RUN_TEST(test_can_node_HeartbeatAtConfiguredPeriod);
  RUN_TEST(test_can_node_DriveTelemetryFollowsEveryHeartbeatOnceSet);
  RUN_TEST(test_can_node_DriveFaultFaultsTheCoreAndTheHeartbeatNamesIt);
  RUN_TEST(test_can_node_SilenceTripsWatchdogAfterTimeout);
  RUN_TEST(test_can_node_CommandsAloneNeverArmTheWatchdog);
  RUN_TEST(test_can_node_WatchdogFaultsTheCoreAndClearRampsThroughSlew);
  RUN_TEST(test_can_node_EstopWinsOverWatchdogSafeTorque);
  RUN_TEST(test_can_node_SeqWrapIsTheNextSampleNotANewRun);
  RUN_TEST(test_can_node_ImpossibleSampleLatchesBadInputInTheCore);
  RUN_TEST(test_can_node_ResetIsRefusedInRunAndAcceptedAfterStop);
  RUN_TEST(test_can_node_EstopLevelReachesTheNextTick);
  RUN_TEST(test_can_node_MalformedFramesAreDroppedAndCounted);
  RUN_TEST(test_can_node_ClearBeforeTheReleaseInOneTickIsDropped);
  RUN_TEST(test_can_node_ClearCountsOnlyAfterTheReleaseAndWhileReleased);
  RUN_TEST(test_can_node_ClearStormWhileEstopHeldClearsNothing);
  RUN_TEST(test_can_node_RefusedResetInRunChangesNothing);
  RUN_TEST(test_can_node_ExperimentStart_AnsweredWithTheCoresReason);
  RUN_TEST(test_can_node_ExperimentStart_OfAnUnknownKindIsDropped);
  RUN_TEST(test_can_node_HardwiredLineHeldDropsAClearAndOutranksTheBus);
  RUN_TEST(test_can_node_HeartbeatCountsRefusedCommands);
  RUN_TEST(test_can_node_HeldAtBootUntilAResetFrameAndAfterAStop);
  return UNITY_END();
}
