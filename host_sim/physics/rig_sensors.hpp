// SPDX-License-Identifier: MIT
// The rig's sensors as the controller sees them: an absolute encoder on the output shaft and two load
// cells (one carrying the rotating bucket, one under the target) read by a sigma-delta ADC at a fixed
// conversion rate, with lag, noise and quantisation, held between conversions.
#ifndef POURSIM_RIG_SENSORS_HPP
#define POURSIM_RIG_SENSORS_HPP

#include <cstdint>
#include <vector>

#include "poursim/poursim.h"
#include "poursim_internal.hpp"

namespace poursim {

// Single-turn count of angle theta [rad]: round(θ·2^bits/2π) wrapped into 0 .. 2^bits − 1.
uint32_t encoder_count(double theta, int bits);

// Standard normal variates from their own splitmix stream (Box–Muller), so that sensor noise never
// draws from the physics' streams.
class Gauss {
 public:
  explicit Gauss(uint64_t seed = 1) : rng_(seed) {}
  double next();

 private:
  Rng rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

// A sigma-delta ADC does not sample the load: its digital filter averages it. The HX711's at 80 samples/s
// settles to a step in 50 ms (4 conversions, a sinc⁴-like response); modelled as the mean of the load
// over the scale_delay_s before each conversion (a box of the same settling time: full response after
// scale_delay_s, half after half of it). scale_delay_s = 0 samples the load at the conversion.
class LoadCell {
 public:
  // Rate, filter span (rounded to whole steps), noise and resolution of config c; the load has been
  // load_g [g] for as long as the filter reaches back (the liquid settled before t = 0); converts once
  // at t = 0.
  void reset(const poursim_config_t &c, double load_g, Gauss &noise);
  // The load after step n (t = n·dt) [g]; converts when a conversion falls due at or before t. Returns
  // the reading held since the last conversion [g].
  int32_t update(uint32_t n, double load_g, Gauss &noise);
  int32_t reading() const { return reading_; }

 private:
  int32_t convert(double load_g, Gauss &noise) const;
  std::vector<double> history_; // the loads of the filter's span, oldest at head_ [g]
  size_t head_ = 0;
  double sum_ = 0.0;            // their sum [g], kept by adding the newest and dropping the oldest
  double dt_ = 0.001, rate_ = 80.0, noise_g_ = 0.0, resolution_g_ = 1.0;
  uint64_t next_ = 1; // index of the next conversion, at next_/rate
  int32_t reading_ = 0;
};

} // namespace poursim

#endif // POURSIM_RIG_SENSORS_HPP
