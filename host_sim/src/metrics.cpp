// SPDX-License-Identifier: MIT
#include "metrics.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace poursim {

void EpisodeMeter::reset(const poursim_config_t &config, const poursim_obs_t &first) {
  dt_ = config.dt;
  gamma_ = config.gamma;
  // The fill of a round bucket of the cross-section's width (poursim_config_t.liquid_density) [L].
  const double r = 0.5 * config.bucket_inner_width;
  litres_ = 1000.0 * M_PI * r * r * config.fill_depth;
  settled_.clear();
  settled_.reserve(static_cast<size_t>(std::lround(config.episode_s / config.dt)));
  steps_ = 0;
  last_ = first;
  peak_omega_ = std::fabs(first.omega);
  peak_alpha_ = 0.0;
  max_theta_ = first.theta;
  ret_ = sum_ = 0.0;
  disc_ = 1.0;
  last_sign_ = 0;
  reversals_ = 0;
  std::fill(std::begin(omega_), std::end(omega_), first.omega);
}

void EpisodeMeter::add(const poursim_obs_t &obs, double command_nm) {
  last_ = obs;
  settled_.push_back(obs.v_target + obs.v_spill);
  peak_omega_ = std::max(peak_omega_, std::fabs(obs.omega));
  max_theta_ = std::max(max_theta_, obs.theta);
  // The slot of step n - kAccelWindow (step 0 = the first observation) is the one this step overwrites.
  double &then = omega_[steps_ % kAccelWindow];
  if (++steps_ >= kAccelWindow)
    peak_alpha_ = std::max(peak_alpha_, std::fabs(obs.omega - then) / (kAccelWindow * dt_));
  then = obs.omega;
  int sign = command_nm > kReversalTorque ? 1 : (command_nm < -kReversalTorque ? -1 : 0);
  if (sign != 0) {
    if (last_sign_ != 0 && sign != last_sign_) ++reversals_;
    last_sign_ = sign;
  }
  ret_ += disc_ * obs.reward;
  disc_ *= gamma_;
  sum_ += obs.reward;
}

poursim_episode_t EpisodeMeter::result() const {
  poursim_episode_t e{};
  e.n_steps = static_cast<int>(settled_.size());
  e.poured = last_.v_target;
  e.spilled = last_.v_spill;
  e.remaining = last_.v_rotating;
  e.ret = ret_;
  e.reward_sum = sum_;
  e.max_theta = max_theta_;
  e.finish_time = -1.0;
  const double fin = settled_.empty() ? 0.0 : settled_.back();
  if (fin >= 0.01) {
    for (size_t t = 0; t < settled_.size(); ++t)
      if (settled_[t] >= 0.99 * fin) {
        e.finish_time = static_cast<double>(t + 1) * dt_;
        break;
      }
  }
  e.liquid_l = litres_;
  e.peak_omega = peak_omega_;
  e.peak_alpha = peak_alpha_;
  e.reversals = reversals_;
  return e;
}

} // namespace poursim
