// SPDX-License-Identifier: MIT
// The figures of one episode, accumulated step by step: one definition for host_sim's summary, the
// trainer's rollouts and the robustness evaluation.
#ifndef POURSIM_METRICS_HPP
#define POURSIM_METRICS_HPP

#include <vector>

#include "poursim/poursim.h"

namespace poursim {

class EpisodeMeter {
 public:
  // Reversals count sign changes of the commanded torque between samples beyond ±this [N·m].
  static constexpr double kReversalTorque = 1.0;
  // Acceleration is the change of θ̇ over this many steps (a 1 ms difference is dominated by contact noise).
  static constexpr int kAccelWindow = 10;

  // Starts an episode whose liquid fills the rotating bucket to config's fill_depth, rewarded by reward.
  void reset(const poursim_config_t &config, const poursim_reward_t &reward, const poursim_obs_t &first);
  // After each step: the observation it produced and the torque commanded for it [N·m].
  void add(const poursim_obs_t &obs, double command_nm);
  // The episode so far (final when the episode is done).
  poursim_episode_t result() const;
  int reversals() const { return reversals_; }
  // The reward of the last step added (poursim_reward_t).
  double last_reward() const { return last_reward_; }

 private:
  double dt_ = 0.001, litres_ = 0.0;
  std::vector<double> settled_; // V_target + V_spill after each step
  double omega_[kAccelWindow] = {}; // θ̇ of the last kAccelWindow steps (ring) [rad/s]
  int steps_ = 0;
  poursim_obs_t last_{};
  poursim_reward_t reward_{};
  double last_reward_ = 0.0;
  double peak_omega_ = 0.0, peak_alpha_ = 0.0, max_theta_ = 0.0, ret_ = 0.0, sum_ = 0.0, disc_ = 1.0;
  int last_sign_ = 0, reversals_ = 0;
};

} // namespace poursim

#endif // POURSIM_METRICS_HPP
