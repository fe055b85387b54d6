// SPDX-License-Identifier: MIT
// The drive's latency and torque–speed envelope (drive.hpp).
#include "drive.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

void Drive::reset(const poursim_config_t &c, uint32_t seed) {
  queue_.assign(static_cast<size_t>(std::max(1, c.command_latency_ticks)), 0.0);
  head_ = 0;
  peak_ = c.motor_peak_torque;
  scale_ = c.torque_scale;
  no_load_ = c.motor_no_load_speed;
  dt_ = c.dt;
  foc_on_ = c.drive == 1;
  if (foc_on_) foc_.reset(c, seed);
}

double Drive::step(double tau_cmd, double omega) {
  const double due = scale_ * queue_[head_];
  queue_[head_] = tau_cmd;
  head_ = (head_ + 1) % queue_.size();
  return foc_on_ ? foc_.step(due, omega, dt_) : limit(due, omega, peak_, no_load_);
}

double Drive::limit(double tau, double omega, double peak, double no_load_speed) {
  double t = std::max(-peak, std::min(peak, tau));
  if (t * omega > 0.0) { // motoring: the back-EMF leaves less voltage for current as the speed rises
    const double avail = peak * std::max(0.0, 1.0 - std::fabs(omega) / no_load_speed);
    t = std::max(-avail, std::min(avail, t));
  }
  return t;
}

} // namespace poursim
