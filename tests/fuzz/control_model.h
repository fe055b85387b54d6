/* SPDX-License-Identifier: MIT */
/* The rules of docs/safety.md as an independent model, checked after every tick of pour_control_step
 * (fuzz_control_step, fuzz_can_node). Written from the document, not from control.c: it tracks only what
 * the rules name (the latest plausible state, the ticks without one, the latched faults). */
#ifndef POUR_FUZZ_CONTROL_MODEL_H
#define POUR_FUZZ_CONTROL_MODEL_H

#include <cstdint>
#include <cstdlib>

#include "fuzz_check.h"

extern "C" {
#include "pour/control.h"
}

class ControlModel {
 public:
  explicit ControlModel(const pour_control_config_t &c, uint8_t n_actions) : c_(c), n_actions_(n_actions) {}

  // Rule 3: what a state must satisfy to be used.
  bool plausible(const pour_state_t &s) const {
    return std::llabs(s.theta_urad) <= c_.plausible_theta_urad && std::llabs(s.omega_urad_s) <= c_.plausible_omega_urad_s &&
           s.v_rotating >= 0 && s.v_target >= 0 && s.v_spill >= 0 &&
           static_cast<int32_t>(s.v_rotating) + s.v_target + s.v_spill <= c_.plausible_volume_sum;
  }

  void check(const pour_control_input_t &in, const pour_control_output_t &out) {
    const pour_safety_config_t &s = c_.safety;
    ++ticks_;
    FUZZ_CHECK(out.tick == ticks_, "tick %u after %u steps", out.tick, ticks_);
    if (in.estop) { // rule 1: zero torque in the same tick, nothing else evaluated
      FUZZ_CHECK(out.torque == 0 && out.mode == POUR_MODE_ESTOP, "e-stop: torque %d mode %u", out.torque, out.mode);
      FUZZ_CHECK((out.faults & (faults_ | POUR_FAULT_ESTOP)) == (faults_ | POUR_FAULT_ESTOP), "e-stop faults %x", out.faults);
      end(out);
      return;
    }
    // Rule 2: a clear acts when the e-stop is released and the controller is in FAULT (an ESTOP becomes FAULT).
    const bool cleared = in.clear_faults && (mode_ == POUR_MODE_FAULT || mode_ == POUR_MODE_ESTOP);
    const uint16_t kept = cleared ? 0u : faults_;
    const uint8_t mode_before = cleared ? POUR_MODE_IDLE : mode_;
    uint16_t may_add = 0;
    bool fresh = false;
    if (in.state_fresh) {
      if (plausible(in.state)) {
        fresh = true;
        theta_ = in.state.theta_urad;
        stale_ = 0;
      } else {
        may_add |= POUR_FAULT_BAD_INPUT;
        FUZZ_CHECK(out.faults & POUR_FAULT_BAD_INPUT, "an implausible state did not latch BAD_INPUT");
      }
    } else if (mode_before == POUR_MODE_RUN && ++stale_ > c_.input_timeout_ms) { // rule 4
      may_add |= POUR_FAULT_STALE_INPUT;
      FUZZ_CHECK(out.faults & POUR_FAULT_STALE_INPUT, "%u ticks without a state did not latch STALE_INPUT", stale_);
    }
    FUZZ_CHECK((out.faults & kept) == kept, "a latched fault cleared itself: %x -> %x", kept, out.faults);
    FUZZ_CHECK((out.faults & ~(kept | may_add)) == 0, "fault without a cause: %x (kept %x)", out.faults, kept);
    FUZZ_CHECK((out.faults != 0) == (out.mode == POUR_MODE_FAULT), "faults %x in mode %u", out.faults, out.mode);
    if (out.mode == POUR_MODE_RUN) { // rule 5: RUN is entered on a fresh, plausible state only
      FUZZ_CHECK(mode_before == POUR_MODE_RUN || (mode_before == POUR_MODE_IDLE && fresh), "RUN from mode %u", mode_before);
      FUZZ_CHECK(out.action < n_actions_, "action %u", out.action);
      // Rule 7, the envelope.
      FUZZ_CHECK(std::abs(out.torque) <= s.tau_limit, "|torque| %d > tau_limit %d", out.torque, s.tau_limit);
      FUZZ_CHECK(std::abs(out.torque - torque_) <= s.slew_per_tick || out.torque == 0,
                 "torque %d -> %d breaks the slew limit %d", torque_, out.torque, s.slew_per_tick);
    } else {
      FUZZ_CHECK(out.mode == POUR_MODE_IDLE || out.mode == POUR_MODE_FAULT, "mode %u without e-stop", out.mode);
      FUZZ_CHECK(out.torque == c_.safe_torque || out.torque == 0, "torque %d in mode %u", out.torque, out.mode);
      FUZZ_CHECK(out.torque == c_.safe_torque || (c_.safe_torque > 0 ? theta_ >= s.theta_max_urad : theta_ <= s.theta_min_urad),
                 "safe torque %d dropped to 0 inside the angle limits", c_.safe_torque);
    }
    FUZZ_CHECK(!(theta_ >= s.theta_max_urad && out.torque > 0), "tilting further at theta %d", theta_);
    FUZZ_CHECK(!(theta_ <= s.theta_min_urad && out.torque < 0), "tilting back further at theta %d", theta_);
    end(out);
  }

 private:
  void end(const pour_control_output_t &out) {
    mode_ = out.mode;
    faults_ = out.faults;
    torque_ = out.torque;
    if (mode_ != POUR_MODE_RUN) stale_ = 0;
  }

  pour_control_config_t c_;
  uint8_t n_actions_;
  uint32_t ticks_ = 0, stale_ = 0;
  uint8_t mode_ = POUR_MODE_IDLE;
  uint16_t faults_ = 0;
  q15_t torque_ = 0;
  int32_t theta_ = 0; // the latest plausible state's tilt (the controller starts from a zero state)
};

// A controller config drawn from the fuzz input: every field in the range pour_control_init accepts, or
// (rarely) outside it, in which case init must refuse it.
template <class Provider>
pour_control_config_t fuzz_control_config(Provider &fdp) {
  pour_control_config_t c = pour_control_default_config();
  if (fdp.ConsumeBool()) return c;
  c.safety.tau_limit = fdp.template ConsumeIntegralInRange<q15_t>(1, 32767);
  c.safety.slew_per_tick = fdp.template ConsumeIntegralInRange<q15_t>(1, 32767);
  c.safety.theta_min_urad = fdp.template ConsumeIntegralInRange<int32_t>(-200000, 0);
  c.safety.theta_max_urad = fdp.template ConsumeIntegralInRange<int32_t>(1, 3000000);
  c.input_timeout_ms = fdp.template ConsumeIntegralInRange<uint16_t>(1, 60);
  c.safe_torque = fdp.template ConsumeIntegralInRange<q15_t>(static_cast<q15_t>(-c.safety.tau_limit), c.safety.tau_limit);
  c.policy_mode = fdp.ConsumeBool() ? POUR_POLICY_SAMPLED : POUR_POLICY_GREEDY;
  c.seed = fdp.template ConsumeIntegral<uint32_t>();
  return c;
}

#endif /* POUR_FUZZ_CONTROL_MODEL_H */
