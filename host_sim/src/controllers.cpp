// SPDX-License-Identifier: MIT
#include "controllers.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

namespace {

// The firmware's defaults with the rig's encoder as the simulator models it.
pour_control_config_t firmware_config(const poursim_config_t &sim) {
  pour_control_config_t c = pour_control_default_config();
  c.sensors.encoder_bits = static_cast<uint8_t>(sim.encoder_bits);
  return c;
}

class FirmwareController : public Controller {
 public:
  FirmwareController(const poursim_weights_file_t &w, bool sampled, const poursim_config_t &sim)
      : file_(w), sampled_(sampled), sim_(sim) {}
  std::string name() const override { return sampled_ ? "firmware (sampled)" : "firmware (greedy)"; }
  void reset(uint32_t seed) override {
    poursim_weights_view(&file_, &view_);
    pour_control_config_t cfg = firmware_config(sim_);
    cfg.policy_mode = sampled_ ? POUR_POLICY_SAMPLED : POUR_POLICY_GREEDY;
    cfg.seed = seed;
    status_ = pour_control_init(&ctl_, &cfg, &view_);
    seq_ = 0;
  }
  double command(const poursim_obs_t &obs) override {
    if (status_ != POUR_OK) return 0.0;
    pour_control_input_t in{};
    in.sensors_fresh = true;
    in.sensors = to_sensor_sample(obs, seq_++);
    pour_control_step(&ctl_, &in, &out_);
    return out_.torque / 32768.0;
  }
  int action() const override { return out_.action; }

 private:
  poursim_weights_file_t file_;
  pour_policy_weights_t view_{};
  bool sampled_;
  poursim_config_t sim_;
  pour_control_t ctl_{};
  pour_control_output_t out_{};
  pour_status_t status_ = POUR_EINVAL;
  uint32_t seq_ = 0;
};

// Shared by the baselines: they see the rig through the firmware's estimator, as the policy does, and
// command through the same envelope.
class EnvelopedController : public Controller {
 public:
  explicit EnvelopedController(const poursim_config_t &sim) : fw_(firmware_config(sim)) {}
  void reset(uint32_t) override {
    pour_safety_init(&safety_, &fw_.safety);
    pour_estimator_init(&est_, &fw_.sensors);
    state_ = pour_state_t{};
    t_ = 0.0;
    seq_ = 0;
  }
  double command(const poursim_obs_t &obs) override {
    const pour_sensors_t sample = to_sensor_sample(obs, seq_++);
    pour_estimator_update(&est_, &sample, &state_);
    double want = request(state_.theta_urad * 1e-6, state_.omega_urad_s * 1e-6);
    t_ += 0.001;
    q15_t cmd = pour_safety_apply(&safety_, poursim_fraction_to_q15(want), state_.theta_urad, state_.omega_urad_s);
    return cmd / 32768.0;
  }

 protected:
  // The torque fraction wanted at tilt theta [rad] and rate omega [rad/s] (both estimated).
  virtual double request(double theta, double omega) = 0;
  double t_ = 0.0; // [s] since reset
 private:
  pour_control_config_t fw_;
  pour_safety_t safety_{};
  pour_estimator_t est_{};
  pour_state_t state_{};
  uint32_t seq_ = 0;
};

// PD tracking of a reference angle; gains in N·m per rad and per rad/s.
double pd(double theta, double omega, double ref, double tau_max) {
  const double kp = 200.0, kd = 20.0;
  return (kp * (ref - theta) - kd * omega) / tau_max;
}

class RateController : public EnvelopedController {
 public:
  RateController(double rate, const poursim_config_t &c) : EnvelopedController(c), rate_(rate), cfg_(c) {}
  std::string name() const override {
    char b[64];
    std::snprintf(b, sizeof b, "constant rate %.2f rad/s", rate_);
    return b;
  }

 protected:
  double request(double theta, double omega) override {
    // The reference runs past the stop so the bucket is pressed onto it, as the paper's policy was.
    double ref = std::min(rate_ * t_, cfg_.theta_max + 0.2);
    return pd(theta, omega, ref, cfg_.tau_max);
  }

 private:
  double rate_;
  poursim_config_t cfg_;
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
  explicit HandController(const poursim_config_t &c) : EnvelopedController(c), cfg_(c) {}
  std::string name() const override { return "hand-written pour"; }

 protected:
  double request(double theta, double omega) override {
    // Fast to just before the liquid reaches the lip (an ideal liquid's onset at this fill is 41°), then
    // slowly on to the stop, so the stream stays thin and is not thrown past the target; the last
    // stretch empties the bucket.
    const double fast = 2.0, slow = 0.3, knee = 0.6; // [rad/s], [rad/s], [rad]
    double t_knee = knee / fast;
    double ref = t_ < t_knee ? fast * t_ : knee + slow * (t_ - t_knee);
    return pd(theta, omega, std::min(ref, cfg_.theta_max + 0.1), cfg_.tau_max);
  }

 private:
  poursim_config_t cfg_;
};

} // namespace

pour_sensors_t to_sensor_sample(const poursim_obs_t &obs, uint32_t seq) {
  return pour_sensors_t{seq, obs.encoder, obs.scale_rotating_g, obs.scale_target_g};
}

std::unique_ptr<Controller> make_firmware_controller(const poursim_weights_file_t &w, bool sampled,
                                                     const poursim_config_t &config) {
  return std::make_unique<FirmwareController>(w, sampled, config);
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
