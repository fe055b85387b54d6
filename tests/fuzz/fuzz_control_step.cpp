// SPDX-License-Identifier: MIT
// Property fuzzer of the 1 kHz control step: a fuzzed controller config, then a sequence of ticks whose
// inputs (fresh or not, any sensor sample, e-stop, clear, link fault, stop, reset, the drive's fault word, a
// parameter write between ticks) come from the fuzz input. After every tick the rules of docs/safety.md must
// hold (control_model.h), and a Reset the core refuses changes nothing else. The drive's word is a level, as a
// board's: a bit, once set, stays until a clear the core would act on reaches the drive (asked with
// pour_control_clear_acceptable, before the step, as board_drive.c does) and its cause is gone.
// A parameter write (pour_params_apply, as both ports put one in force): docs/can.md, "BUSY unless IDLE, or
// FAULT with the controlled stop over: never mid-run, never under e-stop", and "In FAULT the latched faults,
// the brake and the tick count stay through the new configuration".
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>

#include "control_model.h"

extern "C" {
#include "pour/params.h"
#include "pour/weights_compiled.h"
}

namespace {

// A sample near what the rig's sensors read most of the time (a bucket that moves a little each tick, the
// scales around 10 kg), anything at all otherwise.
pour_sensors_t fuzz_sample(FuzzedDataProvider &fdp, uint32_t seq, const pour_control_config_t &c, uint32_t *count) {
  pour_sensors_t s{};
  s.seq = seq;
  const uint32_t turn = 1u << c.sensors.encoder_bits;
  if (fdp.ConsumeBool()) {
    *count = (*count + turn + static_cast<uint32_t>(fdp.ConsumeIntegralInRange<int32_t>(-60, 60))) % turn;
    s.encoder = *count;
    s.scale_rotating_g = fdp.ConsumeIntegralInRange<int32_t>(c.sensors.scale_min_g - 10, c.sensors.scale_max_g + 10);
    s.scale_target_g = fdp.ConsumeIntegralInRange<int32_t>(c.sensors.scale_min_g - 10, c.sensors.scale_max_g + 10);
  } else {
    s.encoder = fdp.ConsumeIntegral<uint32_t>();
    s.scale_rotating_g = fdp.ConsumeIntegral<int32_t>();
    s.scale_target_g = fdp.ConsumeIntegral<int32_t>();
  }
  return s;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  FuzzedDataProvider fdp(data, size);
  const pour_control_config_t cfg = fuzz_control_config(fdp);
  static pour_control_t ctl;
  FUZZ_CHECK(pour_control_init(&ctl, &cfg, &pour_weights_compiled) == POUR_OK, "a valid config was refused");
  ControlModel model(cfg, pour_weights_compiled.n_actions);
  static const bool trace = std::getenv("POUR_FUZZ_TRACE") != nullptr; // replaying a crash: one line per tick
  uint32_t count = 0;
  uint16_t word = 0; // the drive's latched fault word
  pour_control_config_t now = cfg;
  for (uint32_t tick = 0; tick < 4000 && fdp.remaining_bytes() > 0; ++tick) {
    const uint8_t flags = fdp.ConsumeIntegral<uint8_t>();
    pour_control_input_t in{};
    in.sensors_fresh = (flags & 0x0f) != 0; // mostly fresh, as on a healthy link
    in.estop = (flags & 0x70) == 0x70;
    in.clear_faults = (flags & 0x80) != 0;
    const uint8_t more = (flags & 0x0f) == 0x0f ? fdp.ConsumeIntegral<uint8_t>() : 0; // rarer requests
    in.link_fault = (more & 0x01) != 0;
    in.stop = (more & 0x02) != 0;
    in.reset = (more & 0x04) != 0;
    if ((more & 0x08) != 0) word = static_cast<uint16_t>(word | (1u << (more >> 5))); // a drive's fault bit
    in.drive_trusted = (more & 0x10) != 0;
    const bool cause_gone = (more & 0x20) == 0;
    if ((more & 0xC0) == 0xC0) { // a parameter write before the tick: one field of the set, any value
      pour_params_t params;
      pour_params_default(&params, &now, 1u);
      const uint8_t id = fdp.ConsumeIntegralInRange<uint8_t>(0, POUR_PARAM_COUNT - 1u);
      const pour_param_info_t *info = pour_param_info(id);
      const bool writable = pour_params_writable(&ctl);
      const uint8_t mode = static_cast<uint8_t>(ctl.mode);
      const uint16_t faults = ctl.faults;
      if (info != nullptr && pour_params_set(&params, id, fdp.ConsumeIntegralInRange<int32_t>(info->min, info->max)) ==
                                 POUR_PARAM_OK) {
        const pour_status_t st = pour_params_apply(&ctl, &params, &pour_weights_compiled);
        FUZZ_CHECK(writable || st != POUR_OK, "a parameter write was taken in mode %u (writable: no)", mode);
        FUZZ_CHECK(ctl.mode == mode && ctl.faults == faults, "a parameter write changed mode %u -> %u, faults %x -> %x",
                   mode, ctl.mode, faults, ctl.faults);
        if (st == POUR_OK) {
          now = params.control;
          model.reconfigure(now);
        }
      }
    }
    // Repeat the input for a run of ticks (a stale link, a held e-stop) when asked.
    const int repeat = (flags & 0x0f) == 0 ? fdp.ConsumeIntegralInRange<int>(1, 40) : 1;
    if (in.sensors_fresh) in.sensors = fuzz_sample(fdp, tick + 1u, now, &count);
    for (int r = 0; r < repeat; ++r) {
      if (in.clear_faults && cause_gone && pour_control_clear_acceptable(&ctl, &in)) word = 0; // the drive clears first
      in.drive_faults = word;
      // A refused Reset changes nothing but the count of refusals: the same tick without it gives the same.
      static pour_control_t shadow;
      pour_control_output_t shadow_out{};
      if (in.reset && !in.stop) {
        shadow = ctl;
        pour_control_input_t plain = in;
        plain.reset = false;
        pour_control_step(&shadow, &plain, &shadow_out);
      }
      pour_control_output_t out{};
      pour_control_step(&ctl, &in, &out);
      // Refused: one more refusal than the same tick without it (a clear may be refused in that tick too).
      if (in.reset && !in.stop && out.refused == shadow_out.refused + 1u)
        FUZZ_CHECK(out.torque == shadow_out.torque && out.mode == shadow_out.mode && out.faults == shadow_out.faults &&
                       out.brake == shadow_out.brake && ctl.state.theta_urad == shadow.state.theta_urad &&
                       ctl.state.omega_urad_s == shadow.state.omega_urad_s && ctl.safety.torque == shadow.safety.torque,
                   "a refused reset changed the tick: torque %d vs %d, mode %u vs %u", out.torque, shadow_out.torque,
                   out.mode, shadow_out.mode);
      if (trace)
        std::fprintf(stderr, "tick: fresh %d encoder %u scales %d %d estop %d clear %d link %d stop %d reset %d drive %x -> "
                     "mode %u faults %x torque %d\n", in.sensors_fresh, in.sensors.encoder, in.sensors.scale_rotating_g,
                     in.sensors.scale_target_g, in.estop, in.clear_faults, in.link_fault, in.stop, in.reset,
                     in.drive_faults, out.mode, out.faults, out.torque);
      model.check(in, out, ctl.state.theta_urad, ctl.state.omega_urad_s, r == 0);
    }
  }
  return 0;
}
