// SPDX-License-Identifier: MIT
#include "metrics.hpp"

#include "poursim_internal.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <cmath>
#include <iterator>

namespace {

// The reward's keys for host_sim --set and their ranges.
struct RewardKey {
  const char *name;
  double poursim_reward_t::*field;
  double max;
};
constexpr RewardKey kRewardKeys[] = {{"k_target", &poursim_reward_t::k_target, 1e6},
                                     {"k_spill", &poursim_reward_t::k_spill, 1e6},
                                     {"gamma", &poursim_reward_t::gamma, 1.0}};

} // namespace

extern "C" poursim_reward_t poursim_default_reward(void) { return poursim_reward_t{1.0, 5.0, 0.9995}; }

extern "C" int poursim_reward_validate(const poursim_reward_t *r, char *err, size_t err_len) {
  if (r == nullptr) return poursim::set_error(err, err_len, POURSIM_EINVAL, "reward is NULL");
  for (const RewardKey &k : kRewardKeys) {
    const double v = r->*k.field;
    if (!(v >= 0.0 && v <= k.max))
      return poursim::set_error(err, err_len, POURSIM_EINVAL, "reward %s = %g is out of range [0, %g]", k.name, v,
                                k.max);
  }
  return POURSIM_OK;
}

extern "C" int poursim_reward_set(poursim_reward_t *r, const char *key, const char *value, char *err,
                                  size_t err_len) {
  if (r == nullptr || key == nullptr || value == nullptr)
    return poursim::set_error(err, err_len, POURSIM_EINVAL, "reward_set: NULL argument");
  for (const RewardKey &k : kRewardKeys) {
    if (std::strcmp(k.name, key) != 0) continue;
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(value, &end);
    if (end == value || *end != '\0' || errno != 0 || !std::isfinite(v))
      return poursim::set_error(err, err_len, POURSIM_EPARSE, "reward %s: '%s' is not a number", key, value);
    poursim_reward_t next = *r;
    next.*k.field = v;
    const int rc = poursim_reward_validate(&next, err, err_len);
    if (rc == POURSIM_OK) *r = next;
    return rc;
  }
  return poursim::set_error(err, err_len, POURSIM_EINVAL, "unknown key '%s': not a config key (host_sim --help) nor one of the reward's (k_target, k_spill, gamma)", key);
}

namespace poursim {

void EpisodeMeter::reset(const poursim_config_t &config, const poursim_reward_t &reward, const poursim_obs_t &first) {
  dt_ = config.dt;
  reward_ = reward;
  last_reward_ = 0.0;
  litres_ = liquid_litres(config);
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
  last_reward_ = reward_.k_target * obs.v_target - reward_.k_spill * obs.v_spill;
  ret_ += disc_ * last_reward_;
  disc_ *= reward_.gamma;
  sum_ += last_reward_;
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
