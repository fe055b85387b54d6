// SPDX-License-Identifier: MIT
// Encoder and load-cell models (rig_sensors.hpp).
#include "rig_sensors.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

uint32_t encoder_count(double theta, int bits) {
  const long long counts = 1LL << bits;
  long long k = std::llround(theta * static_cast<double>(counts) / (2.0 * M_PI)) % counts;
  if (k < 0) k += counts; // below upright: just under 2^bits
  return static_cast<uint32_t>(k);
}

double Gauss::next() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = rng_.uniform(), u2 = rng_.uniform();
  double r = std::sqrt(-2.0 * std::log(1.0 - u1)); // 1 − u1 in (0, 1]: log is finite
  spare_ = r * std::sin(2.0 * M_PI * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * M_PI * u2);
}

void LoadCell::reset(const poursim_config_t &c, double load_g, Gauss &noise) {
  dt_ = c.dt;
  rate_ = c.scale_rate_hz;
  noise_g_ = c.scale_noise_g;
  resolution_g_ = c.scale_resolution_g;
  const long span = std::max(1L, std::lround(c.scale_delay_s / c.dt));
  history_.assign(static_cast<size_t>(span), load_g);
  sum_ = load_g * static_cast<double>(span);
  head_ = 0;
  next_ = 1;
  reading_ = convert(load_g, noise);
}

int32_t LoadCell::convert(double load_g, Gauss &noise) const {
  // Draw even when the noise is 0, so that the stream's position never depends on the noise level.
  const double x = load_g + noise_g_ * noise.next();
  const double q = resolution_g_ * std::nearbyint(x / resolution_g_);
  return static_cast<int32_t>(std::llround(std::max(-2.0e9, std::min(2.0e9, q)))); // whole grams on the wire
}

int32_t LoadCell::update(uint32_t n, double load_g, Gauss &noise) {
  // The ring holds the loads of steps n−span+1 .. n; a conversion now reports their mean. The sum is
  // refreshed from the ring once a round, so that rounding never accumulates over an episode.
  sum_ += load_g - history_[head_];
  history_[head_] = load_g;
  head_ = (head_ + 1) % history_.size();
  if (head_ == 0) {
    sum_ = 0.0;
    for (double x : history_) sum_ += x;
  }
  const double t = n * dt_;
  if (static_cast<double>(next_) / rate_ <= t + 1e-9 * dt_) {
    reading_ = convert(sum_ / static_cast<double>(history_.size()), noise);
    // Conversions that fell due within this step collapse into this one (rate <= 1/dt by validation).
    while (static_cast<double>(next_) / rate_ <= t + 1e-9 * dt_) ++next_;
  }
  return reading_;
}

} // namespace poursim
