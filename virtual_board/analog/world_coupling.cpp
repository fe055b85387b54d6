// SPDX-License-Identifier: MIT
// The Plant's rotor through the gear to host_sim's bucket world (world_coupling.hpp).
#include "world_coupling.hpp"

#include <algorithm>
#include <cmath>

#include "rig_sensors.hpp"

extern "C" {
#include "pour/drive.h"
}

namespace vb {

double default_gear_efficiency() { return pour_drive_default_config().gear_efficiency_q15 / 32768.0; }

double gear_load_at_motor(double tau_out, double omega_m, double ratio, double eta) {
  return tau_out * omega_m >= 0.0 ? tau_out / (ratio * eta) : tau_out * eta / ratio;
}

WorldCoupling::WorldCoupling(const WorldCouplingOptions& o, Plant* plant) : plant_(plant), o_(o) {
  if (!(std::isfinite(o.stiffness_nm_per_rad) && o.stiffness_nm_per_rad > 0.0)) {
    error_ = "world coupling: stiffness_nm_per_rad must be a finite number > 0";
    plant_ = nullptr;
    return;
  }
  eta_ = o.gear_efficiency == 0.0 ? default_gear_efficiency() : o.gear_efficiency;
  if (!(std::isfinite(eta_) && eta_ >= 0.5 && eta_ <= 1.0)) {
    error_ = "world coupling: gear_efficiency must be in 0.5 .. 1 (or 0: host_sim's full drive's)";
    plant_ = nullptr;
    return;
  }
  if (!(std::isfinite(o.damping_nms) && o.damping_nms >= 0.0)) {
    error_ = "world coupling: damping_nms must be a finite number >= 0";
    plant_ = nullptr;
    return;
  }
  poursim_config_t c = poursim_default_config();
  c.seed = o.seed;
  c.drive = 0;                    // the ideal drive as a torque source: the motor is the plant's
  c.command_latency_ticks = 1;    // its minimum: the gear's torque of step k acts in step k + 1
  c.torque_scale = 1.0;
  c.tau_max = 1000.0;             // the action's scale, beyond any torque the gear carries
  c.motor_peak_torque = 1000.0;   // no clamp: the plant's motor limits itself
  c.motor_no_load_speed = 1000.0; // its maximum: the envelope takes < 0.3 % at the bucket's 2.5 rad/s
  c.motor_rotor_inertia = 0.0;    // the plant's rotor carries J; the world must not count it twice
  char err[POURSIM_ERR_LEN] = "";
  world_ = poursim_create(&c, err, sizeof err);
  if (world_ == nullptr) {
    error_ = std::string("world coupling: ") + err;
    plant_ = nullptr;
    return;
  }
  const poursim_config_t* ep = poursim_episode_config(world_);
  n_ = ep->gear_ratio;
  dt_ = ep->dt;
  tau_max_ = ep->tau_max;
  poursim_observe(world_, &obs_);
  if (o.brake) set_brake(true);
  // The bucket is mounted where the shaft stands now (a world created mid-run, after the empty rig's
  // calibration): the gear's zero and the world's time start here.
  if (plant_ != nullptr) {
    theta_m0_ = plant_->theta();
    t0_ = plant_->time_s();
  }
  if (plant_ != nullptr) plant_->set_load([this](double t, double th, double w) { return load(t, th, w); });
}

WorldCoupling::~WorldCoupling() {
  if (plant_ != nullptr) plant_->set_load(nullptr);
  poursim_destroy(world_);
}

void WorldCoupling::set_brake(bool engaged) {
  if (world_ != nullptr) poursim_set_brake(world_, engaged ? 1 : 0);
}

WorldSensors WorldCoupling::sensors() const {
  WorldSensors s;
  s.step = obs_.step;
  s.encoder = obs_.encoder;
  s.scale_rotating_g = obs_.scale_rotating_g;
  s.scale_target_g = obs_.scale_target_g;
  return s;
}

bool WorldCoupling::sensors_frame(uint8_t node_id, pour_can_frame_t* frame) const {
  auto grams = [](int32_t g) {
    return static_cast<int16_t>(std::max<int32_t>(-POUR_CAN_SCALE_MAX_G, std::min<int32_t>(POUR_CAN_SCALE_MAX_G, g)));
  };
  const pour_can_sensors_t m = {static_cast<uint8_t>(obs_.step & 0xFFu), obs_.encoder, grams(obs_.scale_rotating_g),
                                grams(obs_.scale_target_g)};
  return pour_can_pack_sensors(node_id, &m, frame) == POUR_OK;
}

uint64_t WorldCoupling::trajectory_hash() const { return world_ != nullptr ? poursim_trajectory_hash(world_) : 0u; }

double WorldCoupling::load(double t, double theta_m, double omega_m) {
  if (!ok()) return 0.0;
  // The physics step that ended at t: the gear's torque averaged over its PWM periods, into the world.
  const double next = t0_ + static_cast<double>(obs_.step + 1u) * dt_;
  if (t + 1e-12 >= next && samples_ > 0) {
    last_torque_ = sum_ / samples_;
    sum_ = 0.0;
    samples_ = 0;
    const int rc = poursim_step(world_, last_torque_ / tau_max_, &obs_);
    if (rc != POURSIM_OK) {
      error_ = poursim_world_error(world_);
      if (error_.empty()) error_ = "poursim_step failed";
      return 0.0;
    }
  }
  // The gear: the shaft's angle over N against the bucket's, a spring and a damper at the output.
  const double tau_out = o_.stiffness_nm_per_rad * ((theta_m - theta_m0_) / n_ - obs_.theta) + o_.damping_nms * (omega_m / n_ - obs_.omega);
  sum_ += tau_out;
  ++samples_;
  return gear_load_at_motor(tau_out, omega_m, n_, eta_);
}

// ------------------------------------------------------------------------------------------ EmptyBucket
namespace {
// The empty bucket's inertia about its axis: tests/sim/test_calibration.cpp's 0.038 kg m^2 at the output is
// the 2 kg bucket about its centre and the rotor through 1:20 (2.4e-5 x 20^2 = 0.0096); the plant carries
// the rotor, so the bucket alone is the difference.
constexpr double kEmptyBucketOutputInertia = 0.038;  // [kg m^2], the bucket and the rotor through the gear
}  // namespace

EmptyBucket::EmptyBucket(const WorldCouplingOptions& o, Plant* plant) : plant_(plant), o_(o) {
  c_ = poursim_default_config();
  eta_ = o.gear_efficiency == 0.0 ? default_gear_efficiency() : o.gear_efficiency;
  inertia_ = kEmptyBucketOutputInertia - c_.motor_rotor_inertia * c_.gear_ratio * c_.gear_ratio;
  brake_ = true;
  rng_ = 0x9E3779B97F4A7C15ull ^ o.seed;
  theta_m0_ = plant->theta();
  t0_ = plant->time_s();
  encoder_ = poursim::encoder_count(0.0, c_.encoder_bits);
  plant_->set_load([this](double t, double th, double w) { return load(t, th, w); });
}

EmptyBucket::~EmptyBucket() { plant_->set_load(nullptr); }

double EmptyBucket::gauss() {
  // Box-Muller on a 64-bit LCG (Knuth's MMIX constants): seeded, the same on every host.
  auto uniform = [this]() {
    rng_ = rng_ * 6364136223846793005ull + 1442695040888963407ull;
    return (static_cast<double>(rng_ >> 11) + 0.5) / 9007199254740992.0;
  };
  const double u1 = uniform(), u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

bool EmptyBucket::sensors_frame(uint8_t node_id, pour_can_frame_t* frame) const {
  const pour_can_sensors_t m = {static_cast<uint8_t>(step_ & 0xFFu), encoder_, static_cast<int16_t>(scale_rot_),
                                static_cast<int16_t>(scale_tgt_)};
  return pour_can_pack_sensors(node_id, &m, frame) == POUR_OK;
}

double EmptyBucket::load(double t, double theta_m, double omega_m) {
  const double ts = t_last_ < 0.0 ? 0.0 : t - t_last_;
  t_last_ = t;
  const double tau = o_.stiffness_nm_per_rad * ((theta_m - theta_m0_) / c_.gear_ratio - theta_) +
                     o_.damping_nms * (omega_m / c_.gear_ratio - omega_);
  // The bucket: the gear's torque against the joint's friction (Coulomb, sticking below it, and viscous);
  // the brake holds it up to brake_torque (poursim_set_brake's rating).
  const double hold = c_.friction_coulomb + (brake_ ? c_.brake_torque : 0.0);
  const double moving = omega_;
  if (std::fabs(moving) < 1e-4 && std::fabs(tau) <= hold) {
    omega_ = 0.0;
  } else {
    const double dir = std::fabs(moving) >= 1e-4 ? (moving > 0 ? 1.0 : -1.0) : (tau > 0 ? 1.0 : -1.0);
    const double acc = (tau - hold * dir - c_.friction_viscous * omega_) / inertia_;
    const double w = omega_ + acc * ts;
    omega_ = (w * omega_ < 0.0) ? 0.0 : w;  // friction stops the bucket, never reverses it
  }
  theta_ += omega_ * ts;
  // The rig's sensors at each 1 ms step of the world's clock (dt), as poursim_obs_t reads them.
  while (t + 1e-12 >= t0_ + static_cast<double>(step_ + 1u) * c_.dt) {
    ++step_;
    encoder_ = poursim::encoder_count(theta_, c_.encoder_bits);
    auto reading = [this]() {
      return static_cast<int32_t>(std::round(c_.scale_noise_g * gauss() / c_.scale_resolution_g) * c_.scale_resolution_g);
    };
    scale_rot_ = reading();
    scale_tgt_ = reading();
  }
  return gear_load_at_motor(tau, omega_m, c_.gear_ratio, eta_);
}

}  // namespace vb
