// SPDX-License-Identifier: MIT
// Property fuzzer of the 1 kHz control step: a fuzzed controller config, then a sequence of ticks whose
// inputs (fresh or not, any sensor sample, e-stop, clear, link fault, stop, reset) come from the fuzz input. After every tick the rules
// of docs/safety.md must hold (control_model.h), and a Reset the core refuses changes nothing else.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>

#include "control_model.h"

extern "C" {
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
    in.drive_faults = (more & 0x08) != 0 ? static_cast<uint16_t>(1u << (more >> 5)) : 0; // a drive's fault bit
    in.drive_trusted = (more & 0x10) != 0;
    // Repeat the input for a run of ticks (a stale link, a held e-stop) when asked.
    const int repeat = (flags & 0x0f) == 0 ? fdp.ConsumeIntegralInRange<int>(1, 40) : 1;
    if (in.sensors_fresh) in.sensors = fuzz_sample(fdp, tick + 1u, cfg, &count);
    for (int r = 0; r < repeat; ++r) {
      // A refused Reset changes nothing but the count of refusals: the same tick without it gives the same.
      static pour_control_t shadow;
      pour_control_output_t shadow_out{};
      const uint32_t refused_before = ctl.refused;
      if (in.reset && !in.stop) {
        shadow = ctl;
        pour_control_input_t plain = in;
        plain.reset = false;
        pour_control_step(&shadow, &plain, &shadow_out);
      }
      pour_control_output_t out{};
      pour_control_step(&ctl, &in, &out);
      if (in.reset && !in.stop && out.refused != refused_before)
        FUZZ_CHECK(out.torque == shadow_out.torque && out.mode == shadow_out.mode && out.faults == shadow_out.faults &&
                       out.brake == shadow_out.brake && ctl.state.theta_urad == shadow.state.theta_urad &&
                       ctl.state.omega_urad_s == shadow.state.omega_urad_s && ctl.safety.torque == shadow.safety.torque,
                   "a refused reset changed the tick: torque %d vs %d, mode %u vs %u", out.torque, shadow_out.torque,
                   out.mode, shadow_out.mode);
      if (trace)
        std::fprintf(stderr, "tick: fresh %d encoder %u scales %d %d estop %d clear %d link %d stop %d reset %d -> mode %u "
                     "faults %x torque %d\n", in.sensors_fresh, in.sensors.encoder, in.sensors.scale_rotating_g,
                     in.sensors.scale_target_g, in.estop, in.clear_faults, in.link_fault, in.stop, in.reset, out.mode,
                     out.faults, out.torque);
      model.check(in, out, ctl.state.theta_urad, ctl.state.omega_urad_s, r == 0);
    }
  }
  return 0;
}
