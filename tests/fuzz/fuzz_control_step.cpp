// SPDX-License-Identifier: MIT
// Property fuzzer of the 1 kHz control step: a fuzzed controller config, then a sequence of ticks whose
// inputs (fresh or not, any state, e-stop, clear, link fault, stop, reset) come from the fuzz input. After every tick the rules
// of docs/safety.md must hold (control_model.h).
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>

#include "control_model.h"

extern "C" {
#include "pour/weights_compiled.h"
}

namespace {

// A state near the physical range most of the time, anything at all otherwise.
pour_state_t fuzz_state(FuzzedDataProvider &fdp, uint32_t seq) {
  pour_state_t s{};
  s.seq = seq;
  if (fdp.ConsumeBool()) {
    s.theta_urad = fdp.ConsumeIntegralInRange<int32_t>(-300000, 3200000);
    s.omega_urad_s = fdp.ConsumeIntegralInRange<int32_t>(-60000000, 60000000);
    s.v_rotating = fdp.ConsumeIntegralInRange<q15_t>(0, 32767);
    s.v_target = fdp.ConsumeIntegralInRange<q15_t>(0, static_cast<q15_t>(32767 - s.v_rotating));
    // Up to 200 LSB over the plausible sum (and a little below zero): the edges of rule 3.
    const int room = std::min(32767, 32767 - s.v_rotating - s.v_target + 200);
    s.v_spill = static_cast<q15_t>(fdp.ConsumeIntegralInRange<int>(-2, room));
  } else {
    s.theta_urad = fdp.ConsumeIntegral<int32_t>();
    s.omega_urad_s = fdp.ConsumeIntegral<int32_t>();
    s.v_rotating = fdp.ConsumeIntegral<q15_t>();
    s.v_target = fdp.ConsumeIntegral<q15_t>();
    s.v_spill = fdp.ConsumeIntegral<q15_t>();
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
  for (uint32_t tick = 0; tick < 4000 && fdp.remaining_bytes() > 0; ++tick) {
    const uint8_t flags = fdp.ConsumeIntegral<uint8_t>();
    pour_control_input_t in{};
    in.state_fresh = (flags & 0x0f) != 0; // mostly fresh, as on a healthy link
    in.estop = (flags & 0x70) == 0x70;
    in.clear_faults = (flags & 0x80) != 0;
    const uint8_t more = (flags & 0x0f) == 0x0f ? fdp.ConsumeIntegral<uint8_t>() : 0; // rarer requests
    in.link_fault = (more & 0x01) != 0;
    in.stop = (more & 0x02) != 0;
    in.reset = (more & 0x04) != 0;
    // Repeat the input for a run of ticks (a stale link, a held e-stop) when asked.
    const int repeat = (flags & 0x0f) == 0 ? fdp.ConsumeIntegralInRange<int>(1, 40) : 1;
    if (in.state_fresh) in.state = fuzz_state(fdp, tick);
    for (int r = 0; r < repeat; ++r) {
      pour_control_output_t out{};
      pour_control_step(&ctl, &in, &out);
      if (trace)
        std::fprintf(stderr, "tick: fresh %d theta %d estop %d clear %d link %d stop %d reset %d -> mode %u faults %x torque %d\n",
                     in.state_fresh, in.state.theta_urad, in.estop, in.clear_faults, in.link_fault, in.stop, in.reset,
                     out.mode, out.faults, out.torque);
      model.check(in, out, ctl.state.theta_urad);
    }
  }
  return 0;
}
