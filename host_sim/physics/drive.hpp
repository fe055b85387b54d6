// SPDX-License-Identifier: MIT
// The geared drive between the commanded torque and the bucket: command latency (CAN), peak torque, the
// back-EMF torque–speed line. Its rotor inertia and friction act through Box2D (world.cpp): J·N² in the
// bucket's mass data, Coulomb friction as the joint's motor at zero speed, viscous as a torque −b·ω.
#ifndef POURSIM_DRIVE_HPP
#define POURSIM_DRIVE_HPP

#include <vector>

#include "foc_drive.hpp"
#include "poursim/poursim.h"

namespace poursim {

class Drive {
 public:
  // Latency and limits of config c; the queue starts with zero commands (the drive idles at reset).
  void reset(const poursim_config_t &c, uint32_t seed = 1);
  // Takes this step's command [N·m at the output] and returns the torque the drive delivers in this step
  // at output speed omega [rad/s]: the command of command_latency_ticks steps ago, limited (drive 0) or
  // through the current loop and the motor model (drive 1).
  double step(double tau_cmd, double omega);
  // The full drive latched a fault and asks for the holding brake.
  bool brake_requested() const { return foc_on_ && foc_.brake_requested(); }
  const FocDrive *foc() const { return foc_on_ ? &foc_ : nullptr; }
  // The torque–speed envelope: clamp to ±peak; when the torque drives the motion (motoring), at most
  // peak·(1 − |ω|/ω₀), down to 0 at the no-load speed ω₀. Braking is limited by the peak only.
  static double limit(double tau, double omega, double peak, double no_load_speed);

 private:
  std::vector<double> queue_; // commands in flight, oldest at head_
  size_t head_ = 0;
  double peak_ = 0.0, no_load_ = 0.0, dt_ = 0.001;
  double scale_ = 1.0; // torque_scale: the command as the drive delivers it
  bool foc_on_ = false;
  FocDrive foc_;
};

// Rotor inertia seen at the output: J·N² [kg·m²].
inline double reflected_inertia(const poursim_config_t &c) {
  return c.motor_rotor_inertia * c.gear_ratio * c.gear_ratio;
}

} // namespace poursim

#endif // POURSIM_DRIVE_HPP
