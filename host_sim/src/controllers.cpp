// SPDX-License-Identifier: MIT
#include "controllers.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

namespace {

q15_t saturate_q15(double x) {
  double r = std::nearbyint(x);
  return static_cast<q15_t>(std::max(-32768.0, std::min(32767.0, r)));
}

q15_t volume_q15(double v) {
  double r = std::nearbyint(v * 32768.0);
  return static_cast<q15_t>(std::max(0.0, std::min(32767.0, r)));
}

int32_t urad(double x) {
  double r = std::round(x * 1e6);
  return static_cast<int32_t>(std::max(-2147483648.0, std::min(2147483647.0, r)));
}

class FirmwareController : public Controller {
 public:
  FirmwareController(const poursim_weights_file_t &w, bool sampled) : file_(w), sampled_(sampled) {}
  std::string name() const override { return sampled_ ? "firmware (sampled)" : "firmware (greedy)"; }
  void reset(uint32_t seed) override {
    poursim_weights_view(&file_, &view_);
    pour_control_config_t cfg = pour_control_default_config();
    cfg.policy_mode = sampled_ ? POUR_POLICY_SAMPLED : POUR_POLICY_GREEDY;
    cfg.seed = seed;
    status_ = pour_control_init(&ctl_, &cfg, &view_);
    seq_ = 0;
  }
  double command(const poursim_obs_t &obs) override {
    if (status_ != POUR_OK) return 0.0;
    pour_control_input_t in{};
    in.state_fresh = true;
    in.state = to_firmware_state(obs, seq_++);
    pour_control_step(&ctl_, &in, &out_);
    return out_.torque / 32768.0;
  }
  int action() const override { return out_.action; }

 private:
  poursim_weights_file_t file_;
  pour_policy_weights_t view_{};
  bool sampled_;
  pour_control_t ctl_{};
  pour_control_output_t out_{};
  pour_status_t status_ = POUR_EINVAL;
  uint32_t seq_ = 0;
};

// Shared by the baselines: the same envelope the firmware applies.
class EnvelopedController : public Controller {
 public:
  void reset(uint32_t) override {
    pour_safety_config_t cfg = pour_safety_default_config();
    pour_safety_init(&safety_, &cfg);
    t_ = 0.0;
  }
  double command(const poursim_obs_t &obs) override {
    double want = request(obs);
    t_ += 0.001;
    q15_t cmd = pour_safety_apply(&safety_, saturate_q15(want * 32768.0), urad(obs.theta));
    return cmd / 32768.0;
  }

 protected:
  virtual double request(const poursim_obs_t &obs) = 0;
  double t_ = 0.0; // [s] since reset
 private:
  pour_safety_t safety_{};
};

// PD tracking of a reference angle; gains in N·m per rad and per rad/s.
double pd(const poursim_obs_t &o, double ref, double tau_max) {
  const double kp = 200.0, kd = 20.0;
  return (kp * (ref - o.theta) - kd * o.omega) / tau_max;
}

class RateController : public EnvelopedController {
 public:
  RateController(double rate, const poursim_config_t &c) : rate_(rate), cfg_(c) {}
  std::string name() const override {
    char b[64];
    std::snprintf(b, sizeof b, "constant rate %.2f rad/s", rate_);
    return b;
  }

 protected:
  double request(const poursim_obs_t &o) override {
    // The reference runs past the stop so the bucket is pressed onto it, as the paper's policy was.
    double ref = std::min(rate_ * t_, cfg_.theta_max + 0.2);
    return pd(o, ref, cfg_.tau_max);
  }

 private:
  double rate_;
  poursim_config_t cfg_;
};

class FullTorqueController : public EnvelopedController {
 public:
  std::string name() const override { return "full torque"; }

 protected:
  double request(const poursim_obs_t &) override { return 1.0; }
};

class HandController : public EnvelopedController {
 public:
  explicit HandController(const poursim_config_t &c) : cfg_(c) {}
  std::string name() const override { return "hand-written pour"; }

 protected:
  double request(const poursim_obs_t &o) override {
    // Fast to just before the liquid reaches the lip (an ideal liquid's onset at this fill is 41°), then
    // slowly on to the stop, so the stream stays thin and is not thrown past the target; the last
    // stretch empties the bucket.
    const double fast = 2.0, slow = 0.3, knee = 0.6; // [rad/s], [rad/s], [rad]
    double t_knee = knee / fast;
    double ref = t_ < t_knee ? fast * t_ : knee + slow * (t_ - t_knee);
    return pd(o, std::min(ref, cfg_.theta_max + 0.1), cfg_.tau_max);
  }

 private:
  poursim_config_t cfg_;
};

} // namespace

pour_state_t to_firmware_state(const poursim_obs_t &obs, uint32_t seq) {
  pour_state_t s{};
  s.seq = seq;
  s.theta_urad = urad(obs.theta);
  s.omega_urad_s = urad(obs.omega);
  s.v_rotating = volume_q15(obs.v_rotating);
  s.v_target = volume_q15(obs.v_target);
  s.v_spill = volume_q15(obs.v_spill);
  return s;
}

std::unique_ptr<Controller> make_firmware_controller(const poursim_weights_file_t &w, bool sampled) {
  return std::make_unique<FirmwareController>(w, sampled);
}
std::unique_ptr<Controller> make_rate_controller(double rate, const poursim_config_t &c) {
  return std::make_unique<RateController>(rate, c);
}
std::unique_ptr<Controller> make_full_torque_controller() { return std::make_unique<FullTorqueController>(); }
std::unique_ptr<Controller> make_hand_controller(const poursim_config_t &c) {
  return std::make_unique<HandController>(c);
}

} // namespace poursim
