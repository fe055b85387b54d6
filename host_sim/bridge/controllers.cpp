// SPDX-License-Identifier: MIT
#include "controllers.hpp"

#include "poursim_internal.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

double fill_knee_rad(const poursim_config_t &rig) {
  // A level liquid reaches the lip when the surface through the lip holds the whole fill: a trapezoid,
  // tan θ = 2 (depth - fill) / width, while the fill is at least half the depth; a triangle below that,
  // tan θ = depth² / (2 width fill).
  const double h = rig.bucket_height - rig.bucket_wall, w = rig.bucket_inner_width, d = rig.fill_depth;
  const double onset = d >= 0.5 * h ? std::atan2(2.0 * std::max(0.0, h - d), w) : std::atan2(h * h, 2.0 * w * d);
  return std::max(0.0, onset - kFillKneeMarginRad);
}

pour_control_config_t firmware_config(const poursim_config_t &sim) {
  pour_control_config_t c = pour_control_default_config();
  c.sensors.encoder_bits = static_cast<uint8_t>(sim.encoder_bits);
  if (sim.fill_schedule_l > 0.0 && liquid_litres(sim) > sim.fill_schedule_l)
    c.safety.knee_theta_urad = std::max<int32_t>(1, static_cast<int32_t>(std::lround(fill_knee_rad(sim) * 1e6)));
  return c;
}

void CoreController::reset(uint32_t seed) {
  seq_ = 0;
  sensed_ = due_ = false;
  if (restart_by_reset_ && status_ == POUR_OK) {
    restart_pending_ = true; // the core and its output carry on, as a linked controller's do
    return;
  }
  status_ = init(&ctl_, firmware_config(rig_), seed);
  out_ = pour_control_output_t{};
}

void CoreController::sense(const poursim_obs_t &obs) {
  if (status_ != POUR_OK) return;
  pour_control_input_t in{};
  in.sensors_fresh = true;
  in.sensors = to_sensor_sample(obs, seq_++);
  in.drive_faults = static_cast<uint16_t>(obs.drive_faults); // the full drive's (drive = 1), as a board's reach its core
  in.drive_trusted = obs.drive_trusted != 0;
  if (restart_pending_) { // what LcmLink::request_new_run and the CAN bridge ask for, taken in one tick
    in.clear_faults = in.stop = in.reset = true;
    restart_pending_ = false;
  }
  due_ = pour_control_update(&ctl_, &in);
  sensed_ = true;
}

double CoreController::command(const poursim_obs_t &obs) {
  if (status_ != POUR_OK) return 0.0;
  if (!sensed_) sense(obs);
  sensed_ = false;
  if (due_) decide(&ctl_, *pour_control_state(&ctl_));
  pour_control_shape(&ctl_, &out_);
  return out_.torque / 32768.0;
}

std::string CoreController::failure() const {
  return std::string("the firmware core refused its config or weights: ") + pour_status_name(status_);
}

namespace {

class FirmwareController : public CoreController {
 public:
  FirmwareController(const poursim_weights_file_t &w, bool sampled, const poursim_config_t &sim)
      : CoreController(sim), file_(w), sampled_(sampled) {}
  std::string name() const override { return sampled_ ? "firmware (sampled)" : "firmware (greedy)"; }

 protected:
  pour_status_t init(pour_control_t *ctl, const pour_control_config_t &config, uint32_t seed) override {
    poursim_weights_view(&file_, &view_);
    pour_control_config_t cfg = config;
    cfg.policy_mode = sampled_ ? POUR_POLICY_SAMPLED : POUR_POLICY_GREEDY;
    cfg.seed = seed;
    return pour_control_init(ctl, &cfg, &view_);
  }
  void decide(pour_control_t *ctl, const pour_state_t &) override { pour_control_decide(ctl); }

 private:
  poursim_weights_file_t file_;
  pour_policy_weights_t view_{};
  bool sampled_;
};

// Shared by the baselines: a torque request every tick from the estimated state.
class EnvelopedController : public CoreController {
 public:
  explicit EnvelopedController(const poursim_config_t &sim) : CoreController(sim) {}

 protected:
  pour_status_t init(pour_control_t *ctl, const pour_control_config_t &config, uint32_t) override {
    t_ = 0.0;
    return pour_control_init_external(ctl, &config, 1u);
  }
  void decide(pour_control_t *ctl, const pour_state_t &s) override {
    const double want = request(s.theta_urad * 1e-6, s.omega_urad_s * 1e-6);
    t_ += 0.001;
    pour_control_request(ctl, 0u, poursim_fraction_to_q15(want));
  }
  // The torque fraction wanted at tilt theta [rad] and rate omega [rad/s] (both estimated).
  virtual double request(double theta, double omega) = 0;
  double t_ = 0.0; // [s] since the run started
};

// PD tracking of a reference angle; gains in N·m per rad and per rad/s.
double pd(double theta, double omega, double ref, double tau_max) {
  const double kp = 200.0, kd = 20.0;
  return (kp * (ref - theta) - kd * omega) / tau_max;
}

class RateController : public EnvelopedController {
 public:
  RateController(double rate, const poursim_config_t &c) : EnvelopedController(c), rate_(rate) {}
  std::string name() const override {
    char b[64];
    std::snprintf(b, sizeof b, "constant rate %.2f rad/s", rate_);
    return b;
  }

 protected:
  double request(double theta, double omega) override {
    // The reference runs past the stop so the bucket is pressed onto it, as the paper's policy was.
    double ref = std::min(rate_ * t_, sim_.theta_max + 0.2);
    return pd(theta, omega, ref, sim_.tau_max);
  }

 private:
  double rate_;
};

class FullTorqueController : public EnvelopedController {
 public:
  explicit FullTorqueController(const poursim_config_t &c) : EnvelopedController(c) {}
  std::string name() const override { return "full torque"; }

 protected:
  double request(double, double) override { return 1.0; }
};

class HandController : public EnvelopedController {
 public:
  explicit HandController(const poursim_config_t &c) : EnvelopedController(c) {}
  std::string name() const override { return "hand-written pour"; }

 protected:
  double request(double theta, double omega) override {
    // Fast to just before the liquid reaches the lip (an ideal liquid's onset at this fill is 41°), then
    // slowly on to the stop, so the stream stays thin and is not thrown past the target; the last
    // stretch empties the bucket.
    const double fast = 2.0, slow = 0.3, knee = 0.6; // [rad/s], [rad/s], [rad]
    double t_knee = knee / fast;
    double ref = t_ < t_knee ? fast * t_ : knee + slow * (t_ - t_knee);
    return pd(theta, omega, std::min(ref, sim_.theta_max + 0.1), sim_.tau_max);
  }
};

} // namespace

pour_sensors_t to_sensor_sample(const poursim_obs_t &obs, uint32_t seq) {
  return pour_sensors_t{seq, obs.encoder, obs.scale_rotating_g, obs.scale_target_g};
}

std::unique_ptr<Controller> make_firmware_controller(const poursim_weights_file_t &w, bool sampled,
                                                     const poursim_config_t &config, bool restart_by_reset) {
  auto ctl = std::make_unique<FirmwareController>(w, sampled, config);
  ctl->restart_by_reset(restart_by_reset);
  return ctl;
}
std::unique_ptr<Controller> make_rate_controller(double rate, const poursim_config_t &c) {
  return std::make_unique<RateController>(rate, c);
}
std::unique_ptr<Controller> make_full_torque_controller(const poursim_config_t &c) {
  return std::make_unique<FullTorqueController>(c);
}
std::unique_ptr<Controller> make_hand_controller(const poursim_config_t &c) {
  return std::make_unique<HandController>(c);
}

} // namespace poursim
