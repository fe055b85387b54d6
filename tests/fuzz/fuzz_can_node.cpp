// SPDX-License-Identifier: MIT
// The controller's CAN node with the control step behind it, as the MCU port runs them: frames in (well
// formed for our node, other nodes', or raw garbage), one tick, frames out. After every tick: the rules of
// docs/safety.md on the control step, slew limit included (control_model.h); the sample the core got is the
// last Sensors frame the node accepted, reading for reading; on the bus, the torque frame decodes, carries
// exactly the core's command and mode, stays within tau_limit, and is zero while the e-stop is asserted;
// the heartbeat and identity frames decode. The order of the host's commands within a tick (docs/safety.md,
// transitions): the e-stop is the bus's frames and the hardwired line (sampled before and after the frames);
// the core sees it if either asserted it at any point since the last tick, and a clear only if one arrived
// with both released and no assert came after it in the same tick; every clear not taken is counted, and the
// heartbeat's Refused is the core's refusals plus those, mod 16; the 32-bit sample count runs on by the
// frames' forward distance whatever commands came (a refused Reset changes nothing).
// The port's side as the board composes it (board_loop.c, board_drive.c): the drive's fault word is a level
// that only a clear the core would act on (pour_control_clear_acceptable, asked before the step) clears, once
// its cause is gone; the calibration flow's interlock answers every CalibrationStart from the tick's latest
// sample. docs/can.md: "a start is refused unless the latest sample is recent, upright and empty", "a count out
// of range means REFUSED_NO_SENSORS"; docs/safety.md rule 4: "A clear in a tick whose link fault or drive fault
// word is still set is refused and counted".
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstring>

#include "control_model.h"

extern "C" {
#include "calibration_flow.h"
#include "pour/can_node.h"
#include "pour/weights_compiled.h"
}

namespace {

pour_can_frame_t fuzz_frame(FuzzedDataProvider &fdp, uint8_t node_id) {
  pour_can_frame_t f{};
  const int kind = fdp.ConsumeIntegralInRange<int>(0, 3);
  if (kind == 0) { // anything at all
    f.id = fdp.ConsumeIntegral<uint16_t>() & 0x7ffu;
    f.dlc = fdp.ConsumeIntegralInRange<uint8_t>(0, 8);
    fdp.ConsumeData(f.data, 8);
    return f;
  }
  pour_status_t st = POUR_OK;
  switch (fdp.ConsumeIntegralInRange<int>(0, 2)) { // a well-formed frame of ours (the codec refuses bad values)
    case 0: {                                           // any sample the frame can carry, sensible or not
      pour_can_sensors_t m{fdp.ConsumeIntegral<uint8_t>(), fdp.ConsumeIntegralInRange<uint32_t>(0, 0xFFFFFFu),
                           fdp.ConsumeIntegral<int16_t>(), fdp.ConsumeIntegral<int16_t>()};
      st = pour_can_pack_sensors(node_id, &m, &f);
      break;
    }
    case 1: {
      pour_can_estop_t e{static_cast<uint8_t>(fdp.ConsumeBool())};
      st = pour_can_pack_estop(node_id, &e, &f);
      break;
    }
    default: {
      static const uint8_t commands[] = {POUR_CAN_CMD_CLEAR_ERRORS, POUR_CAN_CMD_STOP, POUR_CAN_CMD_RESET,
                                         POUR_CAN_CMD_CALIBRATION_START};
      st = pour_can_pack_command(node_id, commands[fdp.ConsumeIntegralInRange<int>(0, 3)], &f);
    }
  }
  if (st != POUR_OK) std::memset(&f, 0, sizeof f);
  if (kind == 3) f.id = static_cast<uint16_t>(f.id ^ (1u << fdp.ConsumeIntegralInRange<int>(0, 10))); // one bit off
  return f;
}

// The answer to this tick's CalibrationStart, judged from the documents: RUN and ESTOP refused by name; a start
// may be MEASURING only if the latest sample is at most 20 ms old, in the encoder's range, within 5° of upright
// (0 = upright, below upright wraps) and the rotating scale within ±200 g; else a named refusal. Angles within
// 10 µrad of the 5° edge are not judged (the degrees-to-count rounding there is the firmware's choice).
void check_calibration_answer(uint8_t status, uint8_t mode, const pour_can_sensors_t &s, uint32_t age, uint8_t bits,
                              bool asked) {
  if (!asked) return; // an unasked result (none here: the sequence never runs)
  if (mode == POUR_MODE_RUN) {
    FUZZ_CHECK(status == POUR_CAN_CAL_REFUSED_RUNNING, "a start in RUN answered %u", status);
    return;
  }
  if (mode == POUR_MODE_ESTOP) {
    FUZZ_CHECK(status == POUR_CAN_CAL_REFUSED_ESTOP, "a start in ESTOP answered %u", status);
    return;
  }
  const double turn = std::ldexp(1.0, bits);
  const bool in_range = age != UINT32_MAX && s.encoder < turn;
  const double count = in_range ? (s.encoder >= turn / 2 ? s.encoder - turn : static_cast<double>(s.encoder)) : 0.0;
  const double theta = std::fabs(count * 2.0 * M_PI * 1e6 / turn);
  const bool recent = in_range && age <= 20u;
  if (!recent) {
    FUZZ_CHECK(status == POUR_CAN_CAL_REFUSED_NO_SENSORS, "start with no recent in-range sample (age %u, count %u) "
               "answered %u", age, s.encoder, status);
  } else if (theta > 87266 + 10) {
    FUZZ_CHECK(status == POUR_CAN_CAL_REFUSED_NOT_UPRIGHT, "start at %.0f urad answered %u", theta, status);
  } else if (theta < 87266 - 10 && (s.scale_rotating_g > 200 || s.scale_rotating_g < -200)) {
    FUZZ_CHECK(status == POUR_CAN_CAL_REFUSED_NOT_EMPTY, "start with %d g answered %u", s.scale_rotating_g, status);
  }
  if (status == POUR_CAN_CAL_MEASURING)
    FUZZ_CHECK(recent && theta <= 87266 + 10 && s.scale_rotating_g <= 200 && s.scale_rotating_g >= -200,
               "MEASURING on a sample %u ms old, %.0f urad, %d g", age, theta, s.scale_rotating_g);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  FuzzedDataProvider fdp(data, size);
  const pour_control_config_t cfg = fuzz_control_config(fdp);
  pour_can_node_config_t ncfg = pour_can_node_default_config();
  ncfg.node_id = fdp.ConsumeIntegralInRange<uint8_t>(0, 63);
  ncfg.watchdog_ms = fdp.ConsumeIntegralInRange<uint16_t>(1, 200);
  ncfg.heartbeat_period_ms = fdp.ConsumeIntegralInRange<uint16_t>(1, 200);
  ncfg.can_calibrate = true; // the board's node: it has a drive that measures the motor
  static pour_control_t ctl;
  static pour_can_node_t node;
  FUZZ_CHECK(pour_control_init(&ctl, &cfg, &pour_weights_compiled) == POUR_OK, "a valid config was refused");
  FUZZ_CHECK(pour_can_node_init(&node, &ncfg) == POUR_OK, "a valid node config was refused");
  ControlModel model(cfg, pour_weights_compiled.n_actions);
  // The board's drive, its offsets measured on a quiet bus (it can calibrate), and the flow's interlock.
  static pour_drive_t drv;
  const pour_drive_config_t dcfg = pour_drive_default_config();
  FUZZ_CHECK(pour_drive_init(&drv, &dcfg) == POUR_OK, "the drive's default config was refused");
  const pour_drive_sample_t quiet{{dcfg.offset_nominal, dcfg.offset_nominal, dcfg.offset_nominal}, 0, 0};
  pour_drive_output_t dout;
  for (int k = 0; k < POUR_CURRENT_SENSE_CAL_SAMPLES; ++k) pour_drive_isr(&drv, &quiet, &dout);
  static pour_calibration_flow_t flow;
  pour_calibration_flow_init(&flow, POUR_CAL_OK, nullptr);
  uint16_t word = 0;             // the drive's latched fault word
  uint32_t latest_age = UINT32_MAX; // ms since the latest sample the node took (UINT32_MAX: none yet)
  pour_can_sensors_t latest{};
  static const bool trace = std::getenv("POUR_FUZZ_TRACE") != nullptr; // replaying a crash: one line per tick
  // The e-stop's two sources as the frames and the line samples said them, and the model of pour_commands:
  // a clear pending (it arrived released), the clears dropped so far.
  bool bus_level = false, line_level = false, have_count = false;
  uint32_t count = 0, dropped = 0;
  for (uint32_t tick = 0; tick < 4000 && fdp.remaining_bytes() > 0; ++tick) {
    bool sampled = false;
    bool asserted = false, pending = false;
    const auto asserts = [&] { // a source reports "asserted" (again or anew)
      asserted = true;
      if (pending) ++dropped; // an assert after a clear drops it
      pending = false;
    };
    const auto sample_line = [&] { // the port's hardwired line, before and after the tick's frames (main.c)
      line_level = fdp.ConsumeIntegralInRange<int>(0, 15) == 0 ? !line_level : line_level;
      pour_can_node_estop_line(&node, line_level);
      if (line_level) asserts();
    };
    sample_line();
    const auto counted = [&](const pour_can_sensors_t &m) { // the node's count after one more sample frame
      count = have_count ? count + static_cast<uint8_t>(m.seq_low - (count & 0xFFu)) : m.seq_low;
      have_count = true;
    };
    pour_can_sensors_t last{}; // the last Sensors frame the node accepted this tick
    bool asked_calibration = false;
    if (fdp.ConsumeBool()) { // this tick's sample: mostly what the rig reads (a 17-bit encoder between a
                             // little below upright and the stop, scales within their limits), now and then not
      const bool sane = fdp.ConsumeIntegralInRange<int>(0, 7) != 0;
      const uint32_t below = (1u << 17) - fdp.ConsumeIntegralInRange<uint32_t>(1, 6000);
      const uint32_t enc = sane ? (fdp.ConsumeBool() ? fdp.ConsumeIntegralInRange<uint32_t>(0, 60000) : below)
                                : fdp.ConsumeIntegralInRange<uint32_t>(0, 0xFFFFFFu);
      const int16_t rot = sane ? fdp.ConsumeIntegralInRange<int16_t>(-50, 12000) : fdp.ConsumeIntegral<int16_t>();
      const int16_t tgt = sane ? fdp.ConsumeIntegralInRange<int16_t>(-50, 12000) : fdp.ConsumeIntegral<int16_t>();
      pour_can_sensors_t m{static_cast<uint8_t>(tick), enc, rot, tgt};
      pour_can_frame_t f;
      if (pour_can_pack_sensors(ncfg.node_id, &m, &f) == POUR_OK && pour_can_node_receive(&node, &f) == POUR_CAN_RX_OK) {
        sampled = true;
        last = m;
        counted(m);
      }
    }
    const int n_rx = fdp.ConsumeIntegralInRange<int>(0, 3);
    for (int k = 0; k < n_rx; ++k) {
      const pour_can_frame_t f = fuzz_frame(fdp, ncfg.node_id);
      pour_can_sensors_t m{};
      if (pour_can_node_receive(&node, &f) != POUR_CAN_RX_OK) continue;
      const uint8_t cmd = static_cast<uint8_t>(f.id & POUR_CAN_CMD_MASK);
      pour_can_estop_t e{};
      if (pour_can_unpack_sensors(&f, &m) == POUR_CAN_RX_OK) {
        sampled = true;
        last = m;
        counted(m);
      } else if (cmd == POUR_CAN_CMD_ESTOP && pour_can_unpack_estop(&f, &e) == POUR_CAN_RX_OK) {
        bus_level = e.assert_estop != 0u;
        if (bus_level) asserts();
      } else if (cmd == POUR_CAN_CMD_CALIBRATION_START) {
        asked_calibration = true;
      } else if (cmd == POUR_CAN_CMD_CLEAR_ERRORS) {
        if (bus_level || line_level) {
          ++dropped; // held: dropped where it arrives
        } else {
          pending = true;
        }
      }
    }
    sample_line();
    if (pending && asserted) { // assert, release, clear within the tick: the core sees the assert
      ++dropped;
      pending = false;
    }
    pour_control_input_t in{};
    pour_can_node_begin_tick(&node, &in);
    FUZZ_CHECK(in.sensors_fresh == sampled, "fresh %d after %s", in.sensors_fresh, sampled ? "a sample" : "none");
    if (sampled)
      FUZZ_CHECK((in.sensors.seq & 0xFFu) == last.seq_low && in.sensors.encoder == last.encoder &&
                     in.sensors.scale_rotating_g == last.scale_rotating_g &&
                     in.sensors.scale_target_g == last.scale_target_g,
                 "the core got seq %u encoder %u scales %d/%d, the frame said %u %u %d/%d", in.sensors.seq,
                 in.sensors.encoder, in.sensors.scale_rotating_g, in.sensors.scale_target_g, last.seq_low, last.encoder,
                 last.scale_rotating_g, last.scale_target_g);
    FUZZ_CHECK(in.estop == (bus_level || line_level || asserted),
               "e-stop %d, the frames said level %d, the line %d, asserted %d", in.estop, bus_level, line_level, asserted);
    FUZZ_CHECK(in.clear_faults == pending, "clear %d, the frames and the line said %d", in.clear_faults, pending);
    FUZZ_CHECK(node.commands.clears_dropped == dropped, "%u clears dropped, the frames and the line say %u",
               node.commands.clears_dropped, dropped);
    if (sampled) {
      FUZZ_CHECK(in.sensors.seq == count, "sample count %u, expected %u", in.sensors.seq, count);
    }
    // The drive's word: a bit now and then, held until a clear the core would act on reaches the drive first
    // and its cause is gone (board_drive.c's order).
    const uint8_t drive_bits = fdp.ConsumeIntegral<uint8_t>();
    if ((drive_bits & 0x0f) == 0) word = static_cast<uint16_t>(word | (1u << (drive_bits >> 4)));
    if (in.clear_faults && (drive_bits & 0x10) == 0 && pour_control_clear_acceptable(&ctl, &in)) word = 0;
    in.drive_faults = word;
    in.drive_trusted = (drive_bits & 0x20) != 0;
    pour_control_output_t out{};
    pour_control_step(&ctl, &in, &out);
    model.check(in, out, ctl.state.theta_urad);
    pour_calibration_flow_sense(&flow, &node, &drv, &in.sensors, in.sensors_fresh, cfg.sensors.encoder_bits);
    (void)pour_can_node_take_calibration_start(&node); // the interlock is judged here; the sequence is not run
    if (sampled) {
      latest = last;
      latest_age = 0;
    } else if (latest_age != UINT32_MAX) {
      ++latest_age;
    }
    pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
    const uint8_t n_tx = pour_can_node_end_tick(&node, &out, fdp.ConsumeIntegral<uint8_t>(), tx);
    FUZZ_CHECK(n_tx >= 1 && n_tx <= POUR_CAN_NODE_MAX_TX, "%u frames", n_tx);
    pour_can_torque_t t{};
    FUZZ_CHECK(pour_can_unpack_torque(&tx[0], &t) == POUR_CAN_RX_OK && tx[0].id == pour_can_id(ncfg.node_id, POUR_CAN_CMD_TORQUE),
               "the first frame is not our torque frame (id 0x%03x)", tx[0].id);
    FUZZ_CHECK(t.torque == out.torque && t.mode == out.mode, "the torque frame says %d/%u, the core %d/%u", t.torque,
               t.mode, out.torque, out.mode);
    // After the torque frame: the heartbeat and identity when due, a CalibrationResult when one was asked for;
    // each decodes.
    for (uint8_t k = 1; k < n_tx; ++k) {
      const uint8_t cmd = static_cast<uint8_t>(tx[k].id & POUR_CAN_CMD_MASK);
      pour_can_heartbeat_t hb{};
      pour_can_identity_t id{};
      pour_can_calibration_result_t cal{};
      const bool ok = (cmd == POUR_CAN_CMD_HEARTBEAT && pour_can_unpack_heartbeat(&tx[k], &hb) == POUR_CAN_RX_OK) ||
                      (cmd == POUR_CAN_CMD_IDENTITY && pour_can_unpack_identity(&tx[k], &id) == POUR_CAN_RX_OK) ||
                      (cmd == POUR_CAN_CMD_CALIBRATION_RESULT &&
                       pour_can_unpack_calibration_result(&tx[k], &cal) == POUR_CAN_RX_OK);
      FUZZ_CHECK(ok, "frame %u (cmd 0x%02x) does not decode", k, cmd);
      if (cmd == POUR_CAN_CMD_CALIBRATION_RESULT) check_calibration_answer(cal.status, out.mode, latest, latest_age,
                                                                           cfg.sensors.encoder_bits, asked_calibration);
      if (cmd == POUR_CAN_CMD_HEARTBEAT)
        FUZZ_CHECK(hb.mode == out.mode && hb.refused == ((out.refused + dropped) & POUR_CAN_REFUSED_MAX),
                   "heartbeat mode %u refused %u; the core says %u, %u refused, %u clears dropped", hb.mode, hb.refused,
                   out.mode, out.refused, dropped);
    }
    if (trace)
      std::fprintf(stderr, "tick %u: fresh %d estop %d clear %d | core mode %u faults %x torque %d | link fault %d since_valid %u | bus %d\n",
                   tick, in.sensors_fresh, in.estop, in.clear_faults, ctl.mode, ctl.faults, ctl.safety.torque,
                   in.link_fault, node.ms_since_valid, t.torque);
    if (in.estop) FUZZ_CHECK(t.torque == 0, "torque %d on the bus during e-stop", t.torque);
    FUZZ_CHECK(std::abs(t.torque) <= cfg.safety.tau_limit, "bus torque %d > tau_limit %d", t.torque, cfg.safety.tau_limit);
  }
  return 0;
}
