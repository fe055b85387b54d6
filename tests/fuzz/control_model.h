/* SPDX-License-Identifier: MIT */
/* The safety rules of docs/safety.md and of pour_control_step's contract (control.h), checked after every
 * tick (fuzz_control_step, fuzz_can_node). Written from the documents, not from control.c: it tracks only
 * what the rules name (the ticks without a sample, the latched faults, the last command, the speed band). What the
 * supervisor proves and how the controlled stop steers are for their own tests; here they must stay
 * inside the envelope like everything else. */
#ifndef POUR_FUZZ_CONTROL_MODEL_H
#define POUR_FUZZ_CONTROL_MODEL_H

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>

#include "fuzz_check.h"

extern "C" {
#include "pour/control.h"
}

class ControlModel {
 public:
  // Before its first tick the controller is in IDLE at zero torque: power-on, nothing on the wire yet.
  explicit ControlModel(const pour_control_config_t &c, uint8_t n_actions) : c_(c), n_actions_(n_actions), torque_(0) {}

  // Rule 5: a raw sample no sensor can give (a count beyond the encoder's bits, a scale beyond its range).
  bool raw_plausible(const pour_sensors_t &s) const {
    const pour_sensors_config_t &k = c_.sensors;
    return s.encoder < (1u << k.encoder_bits) && s.scale_rotating_g >= k.scale_min_g &&
           s.scale_rotating_g <= k.scale_max_g && s.scale_target_g >= k.scale_min_g && s.scale_target_g <= k.scale_max_g;
  }

  // theta, omega: the state the core steers by (its latest estimate): the angle limits and the speed band
  // are about that state, and which samples the supervisor accepts (seq advancing) is its business.
  // new_seq: this tick's sample carries a seq the core has not seen (the fuzzer repeats inputs verbatim).
  // omega INT32_MIN: not known to the caller, the band is not checked.
  void check(const pour_control_input_t &in, const pour_control_output_t &out, int32_t theta,
             int32_t omega = INT32_MIN, bool new_seq = false) {
    const pour_safety_config_t &s = c_.safety;
    ++ticks_;
    FUZZ_CHECK(out.tick == ticks_, "tick %u after %u steps", out.tick, ticks_);
    if (in.estop) { // e-stop: zero torque in the same tick, brake on, power cut, whatever else the input says
      FUZZ_CHECK(out.torque == 0 && out.mode == POUR_MODE_ESTOP && out.brake && !out.power,
                 "e-stop: torque %d mode %u brake %d power %d", out.torque, out.mode, out.brake, out.power);
      FUZZ_CHECK((out.faults & (faults_ | POUR_FAULT_ESTOP)) == (faults_ | POUR_FAULT_ESTOP), "e-stop faults %x", out.faults);
      FUZZ_CHECK(out.refused == refused_ + (in.stop ? 1u : 0u) + (in.reset ? 1u : 0u),
                 "refused %u after %u in ESTOP (stop %d reset %d)", out.refused, refused_, in.stop, in.reset);
      end(out);
      return;
    }
    // The mode the tick's requests leave before the state is looked at: a released e-stop, a link fault
    // and a drive fault are FAULT; a clear takes FAULT to IDLE (all faults cleared) once the active stop is over; stop
    // takes RUN to IDLE; a reset is taken in IDLE, or in FAULT once the active stop is over; a refused
    // Stop, Reset or clear is counted.
    uint8_t mode = mode_ == POUR_MODE_ESTOP || in.link_fault || in.drive_faults != 0 ? static_cast<uint8_t>(POUR_MODE_FAULT)
                                                                                   : mode_;
    const bool stopping = mode_ == POUR_MODE_FAULT && power_; // the last tick ran the active stop
    uint16_t kept = faults_;
    // "A clear in a tick whose link fault or drive fault word is still set is refused and counted" (rule 4).
    const bool level = in.link_fault || in.drive_faults != 0;
    const bool clear_refused = in.clear_faults && mode == POUR_MODE_FAULT && (stopping || level);
    if (in.clear_faults && mode == POUR_MODE_FAULT && !clear_refused) {
      kept = 0;
      mode = POUR_MODE_IDLE;
    }
    const bool stop_refused = in.stop && mode != POUR_MODE_RUN;
    if (in.stop && mode == POUR_MODE_RUN) mode = POUR_MODE_IDLE;
    const bool reset_refused = in.reset && (mode == POUR_MODE_RUN || (mode == POUR_MODE_FAULT && stopping));
    FUZZ_CHECK(out.refused == refused_ + (clear_refused ? 1u : 0u) + (stop_refused ? 1u : 0u) + (reset_refused ? 1u : 0u),
               "refused %u after %u (clear %d stop %d reset %d in mode %u)", out.refused, refused_, in.clear_faults,
               in.stop, in.reset, mode);
    stale_ = in.sensors_fresh ? 0u : stale_ + 1u;
    if (in.sensors_fresh && new_seq && !raw_plausible(in.sensors))
      FUZZ_CHECK(out.faults & POUR_FAULT_BAD_INPUT, "an implausible sample did not latch BAD_INPUT");
    if (in.link_fault) FUZZ_CHECK(out.faults & POUR_FAULT_LINK, "a link fault did not latch LINK");
    if (in.drive_faults != 0) FUZZ_CHECK(out.faults & POUR_FAULT_DRIVE, "a drive fault did not latch DRIVE");
    // "the core stays in FAULT, and a brake that held stays engaged" (rule 4), whatever else the tick says.
    if (level)
      FUZZ_CHECK(out.mode == POUR_MODE_FAULT && !(held_ && out.power), "a level fault with clear %d: mode %u power %d",
                 in.clear_faults, out.mode, out.power);
    FUZZ_CHECK((out.faults & kept) == kept, "a latched fault cleared itself: %x -> %x", kept, out.faults);
    const uint16_t new_bits = static_cast<uint16_t>(out.faults & ~kept);
    FUZZ_CHECK((new_bits & ~POUR_FAULT_ALL) == 0 && !(new_bits & POUR_FAULT_ESTOP) && (in.link_fault || !(new_bits & POUR_FAULT_LINK)) &&
                   (in.drive_faults != 0 || !(new_bits & POUR_FAULT_DRIVE)),
               "fault without a cause: %x (kept %x)", out.faults, kept);
    FUZZ_CHECK((out.faults != 0) == (out.mode == POUR_MODE_FAULT), "faults %x in mode %u", out.faults, out.mode);
    FUZZ_CHECK(out.brake == !out.power, "brake %d and power %d together", out.brake, out.power);
    FUZZ_CHECK(std::abs(out.torque) <= s.tau_limit, "|torque| %d > tau_limit %d", out.torque, s.tau_limit);
    if (out.mode == POUR_MODE_RUN) { // RUN is entered on a fresh state only, and never outlives the input timeout
      FUZZ_CHECK(mode == POUR_MODE_RUN || (mode == POUR_MODE_IDLE && in.sensors_fresh), "RUN from mode %u", mode);
      FUZZ_CHECK(stale_ <= c_.input_timeout_ms, "RUN after %u ticks without a state", stale_);
      FUZZ_CHECK(out.action < n_actions_ && out.power, "action %u power %d", out.action, out.power);
    } else if (out.mode == POUR_MODE_IDLE) { // braked, on the way from the last command to the safe torque
      FUZZ_CHECK(out.brake && on_the_way(out.torque, torque_), "torque %d in IDLE after %d", out.torque, torque_);
    } else {
      FUZZ_CHECK(out.mode == POUR_MODE_FAULT, "mode %u without e-stop", out.mode);
      // Once a fault's stop is over the brake holds until a clear: no Reset, sample or storm releases it.
      FUZZ_CHECK(!(held_ && mode == POUR_MODE_FAULT && out.power), "the brake released in FAULT after the stop ended");
    }
    // Continuity across every transition (power-on, stop, reset, clear, a fault, the stop's end): at most the
    // slew limit from the last command, or less torque toward zero, which never waits ...
    const auto toward_zero = [&out](int32_t from) {
      return (from >= 0 && out.torque >= 0 && out.torque <= from) || (from <= 0 && out.torque <= 0 && out.torque >= from);
    };
    FUZZ_CHECK(std::abs(out.torque - torque_) <= s.slew_per_tick || toward_zero(torque_),
               "torque %d -> %d breaks the slew limit %d (mode %u -> %u)", torque_, out.torque, s.slew_per_tick, mode_,
               out.mode);
    // ... and no torque that speeds the bucket beyond ±omega_max: τ <= max(K (ω_max - θ̇), 0) and
    // τ >= min(-K (ω_max + θ̇), 0), K = governor_gain per rad/s, 1 LSB for rounding.
    if (out.power && omega != INT32_MIN) {
      const int64_t w = std::clamp<int64_t>(omega, -POUR_SAFETY_OMEGA_MAX_URAD_S, POUR_SAFETY_OMEGA_MAX_URAD_S);
      const int64_t hi = (static_cast<int64_t>(s.omega_max_urad_s) - w) * s.governor_gain / 1000000;
      const int64_t lo = (-static_cast<int64_t>(s.omega_max_urad_s) - w) * s.governor_gain / 1000000;
      FUZZ_CHECK(out.torque <= std::max<int64_t>(hi, 0) + 1 && out.torque >= std::min<int64_t>(lo, 0) - 1,
                 "torque %d speeds the bucket beyond the band at %d urad/s", out.torque, omega);
    }
    // Angle limits, in every mode: no torque that tilts further past a limit.
    FUZZ_CHECK(!(theta >= s.theta_max_urad && out.torque > 0), "tilting further at theta %d", theta);
    FUZZ_CHECK(!(theta <= s.theta_min_urad && out.torque < 0), "tilting back further at theta %d", theta);
    end(out);
  }

 private:
  void end(const pour_control_output_t &out) {
    mode_ = out.mode;
    faults_ = out.faults;
    torque_ = out.torque;
    power_ = out.power;
    refused_ = out.refused;
    held_ = (out.mode == POUR_MODE_FAULT || out.mode == POUR_MODE_ESTOP) && !out.power;
  }

  // A parameter write put a new configuration in force (pour_params_apply): docs/can.md, "In FAULT the latched
  // faults, the brake and the tick count stay through the new configuration"; the command on the wire stays,
  // within the new clamp.
 public:
  void reconfigure(const pour_control_config_t &c) {
    c_ = c;
    torque_ = static_cast<q15_t>(std::clamp<int32_t>(torque_, -c.safety.tau_limit, c.safety.tau_limit));
  }

 private:
  // Between the last command and the safe torque, or between it and zero (the safe torque cut at a limit).
  bool on_the_way(int32_t x, int32_t from) const {
    const auto between = [&](int32_t to) { return std::min(from, to) <= x && x <= std::max(from, to); };
    return between(c_.safe_torque) || between(0);
  }

  pour_control_config_t c_;
  uint8_t n_actions_;
  uint32_t ticks_ = 0, stale_ = 0;
  uint8_t mode_ = POUR_MODE_IDLE;
  uint16_t faults_ = 0;
  q15_t torque_;
  bool power_ = false;  // the last tick drove the motor (RUN, the active stop)
  bool held_ = false;   // the last tick was FAULT or ESTOP with the brake holding (the stop over, or none)
  uint32_t refused_ = 0;
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
  c.safety.omega_max_urad_s = fdp.template ConsumeIntegralInRange<int32_t>(1, POUR_SAFETY_OMEGA_MAX_URAD_S);
  c.safety.alpha_max_urad_s2 = fdp.template ConsumeIntegralInRange<int32_t>(1000, INT32_MAX);
  c.safety.omega_slack_urad_s = fdp.template ConsumeIntegralInRange<int32_t>(1, POUR_SAFETY_OMEGA_MAX_URAD_S);
  c.safety.governor_gain = fdp.template ConsumeIntegralInRange<q15_t>(1, 32767);
  c.safety.knee_theta_urad = fdp.ConsumeBool() ? 0 : fdp.template ConsumeIntegralInRange<int32_t>(1, POUR_SAFETY_KNEE_MAX_URAD);
  c.safety.slow_omega_urad_s = fdp.template ConsumeIntegralInRange<int32_t>(1, POUR_SAFETY_OMEGA_MAX_URAD_S);
  c.safety.knee_decel_urad_s2 = fdp.template ConsumeIntegralInRange<int32_t>(1000, POUR_SAFETY_DECEL_MAX_URAD_S2);
  c.safety.slow_torque_ff = fdp.template ConsumeIntegralInRange<q15_t>(0, 32767);
  c.safety.slow_ki_per_s = fdp.template ConsumeIntegralInRange<uint16_t>(0, 65535);
  c.sensors.encoder_bits = fdp.template ConsumeIntegralInRange<uint8_t>(POUR_ENCODER_BITS_MIN, POUR_ENCODER_BITS_MAX);
  c.sensors.bandwidth_rad_s = fdp.template ConsumeIntegralInRange<uint16_t>(1, 1000);
  c.sensors.scale_min_g = fdp.template ConsumeIntegralInRange<int32_t>(-POUR_SCALE_LIMIT_G, 0);
  c.sensors.scale_max_g = fdp.template ConsumeIntegralInRange<int32_t>(1, POUR_SCALE_LIMIT_G);
  c.sensors.mass_min_g = fdp.template ConsumeIntegralInRange<int32_t>(1, 20000);
  c.sensors.jump_max_urad = fdp.template ConsumeIntegralInRange<int32_t>(1, 1000000);
  c.input_timeout_ms = fdp.template ConsumeIntegralInRange<uint16_t>(1, 60);
  c.safe_torque = fdp.template ConsumeIntegralInRange<q15_t>(static_cast<q15_t>(-c.safety.tau_limit), c.safety.tau_limit);
  c.policy_mode = fdp.ConsumeBool() ? POUR_POLICY_SAMPLED : POUR_POLICY_GREEDY;
  c.seed = fdp.template ConsumeIntegral<uint32_t>();
  return c;
}

#endif /* POUR_FUZZ_CONTROL_MODEL_H */
