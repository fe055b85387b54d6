// SPDX-License-Identifier: MIT
// Whole episodes in C for the trainer: a float softmax-linear policy decides every P steps of RUN inside the
// firmware's own pipeline (estimator, supervisor, envelope with the motion limits, controlled stop), and
// the arrays Python asked for are filled. The episode itself is
// run_episode's (episode_run.cpp), as host_sim's are.
#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

extern "C" {
#include "pour/control.h"
}
#include "controllers.hpp"
#include "episode_run.hpp"
#include "metrics.hpp"
#include "poursim/poursim.h"
#include "poursim_internal.hpp"
#include "world.hpp"

using poursim::set_error;

namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Features = Eigen::Matrix<double, 1, POURSIM_N_FEATURES>;

int validate_policy(const poursim_policy_t *p, char *err, size_t err_len) {
  if (p == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "policy is NULL");
  if (p->n_actions < 2 || p->n_actions > POURSIM_MAX_ACTIONS)
    return set_error(err, err_len, POURSIM_EINVAL, "policy n_actions %d outside 2..%d", p->n_actions,
                     POURSIM_MAX_ACTIONS);
  if (p->decision_period < 1)
    return set_error(err, err_len, POURSIM_EINVAL, "policy decision_period %d < 1", p->decision_period);
  if (p->w == nullptr || p->levels == nullptr)
    return set_error(err, err_len, POURSIM_EINVAL, "policy weights or levels are NULL");
  for (int i = 0; i < POURSIM_N_FEATURES * p->n_actions; ++i)
    if (!std::isfinite(p->w[i])) return set_error(err, err_len, POURSIM_EINVAL, "policy w[%d] is not finite", i);
  for (int i = 0; i < p->n_actions; ++i)
    if (!(p->levels[i] >= -1.0 && p->levels[i] <= 1.0))
      return set_error(err, err_len, POURSIM_EINVAL, "policy level[%d] outside [-1, 1]", i);
  if (!(p->theta_max > p->theta_min) || !(p->omega_max > 0.0))
    return set_error(err, err_len, POURSIM_EINVAL, "policy normalisation ranges are empty");
  if (!(std::isfinite(p->k_reversal) && p->k_reversal >= 0.0))
    return set_error(err, err_len, POURSIM_EINVAL, "policy k_reversal %g: want a finite value >= 0", p->k_reversal);
  return poursim_reward_validate(&p->reward, err, err_len);
}

// The features of the weights.h spec, from the state the firmware's estimator makes of the sensors.
Features features_of(const poursim_policy_t *p, const pour_state_t &s) {
  Features x;
  poursim_features(p, s.theta_urad * 1e-6, s.omega_urad_s * 1e-6, s.v_rotating / 32768.0, s.v_target / 32768.0,
                   s.v_spill / 32768.0, x.data());
  return x;
}

} // namespace

extern "C" int16_t poursim_fraction_to_q15(double fraction) {
  if (std::isnan(fraction)) return 0;
  const double q = std::floor(fraction * 32768.0 + 0.5); // half up, as the firmware rounds
  return static_cast<int16_t>(q < -32768.0 ? -32768.0 : (q > 32767.0 ? 32767.0 : q));
}

namespace {

// The trainer's float policy as the decision of the firmware's pipeline (CoreController): when a decision
// is due it picks an action from the features of the state the core estimated (greedy or sampled), and
// the level goes as a request through the core's envelope, supervisor and controlled stop. As a StepHook
// it fills the arrays Python asked for.
class RolloutPolicy : public poursim::CoreController, public poursim::StepHook {
 public:
  RolloutPolicy(const poursim_policy_t *policy, const poursim_config_t &config, const poursim_rollout_buffers_t *buf)
      : CoreController(config), p_(policy), buf_(buf), W_(policy->w, POURSIM_N_FEATURES, policy->n_actions),
        probs_(policy->n_actions) {}
  std::string name() const override { return "rollout"; }

 protected:
  pour_status_t init(pour_control_t *ctl, const pour_control_config_t &config, uint32_t seed) override {
    // Sampling draws from its own stream so that greedy and sampled runs share the liquid of a seed.
    rng_ = poursim::Rng(0xA5A5A5A5ULL ^ (static_cast<unsigned long long>(seed) * 0x100000001B3ULL));
    decision_ = -1;
    reversals_ = 0;
    t_ = 0;
    return pour_control_init_external(ctl, &config, static_cast<uint16_t>(p_->decision_period));
  }
  void decide(pour_control_t *ctl, const pour_state_t &state) override {
    decide_action(state);
    pour_control_request(ctl, static_cast<uint8_t>(action_), poursim_fraction_to_q15(p_->levels[action_]));
  }


 public:
  void after_step(const poursim_obs_t &o, double a, const poursim::EpisodeMeter &meter) override {
    t_ = static_cast<int>(o.step) - 1;
    // The policy's reward, and training's shaping: each torque reversal costs k_reversal (0: none).
    const int new_reversals = meter.reversals() - reversals_;
    reversals_ += new_reversals;
    const double r = meter.last_reward() - p_->k_reversal * new_reversals;
    if (buf_ == nullptr) return;
    if (decision_ >= 0 && decision_ < buf_->capacity && buf_->rewards != nullptr) buf_->rewards[decision_] += r;
    if (t_ < buf_->step_capacity) {
      if (buf_->step_rewards != nullptr) buf_->step_rewards[t_] = r;
      if (buf_->step_theta != nullptr) buf_->step_theta[t_] = o.theta;
      if (buf_->step_torque != nullptr) buf_->step_torque[t_] = a;
    }
  }
  int decisions() const { return decision_ + 1; }

 private:
  void decide_action(const pour_state_t &state) {
    ++decision_;
    const int n_act = p_->n_actions;
    Features x = features_of(p_, state);
    Eigen::VectorXd logits = (x * W_).transpose();
    probs_ = (logits.array() - logits.maxCoeff()).exp();
    probs_ /= probs_.sum();
    if (p_->greedy) {
      Eigen::Index best = 0;
      logits.maxCoeff(&best); // first maximum: ties go to the lowest index
      action_ = static_cast<int>(best);
    } else {
      double u = rng_.uniform(), acc = 0.0;
      action_ = n_act - 1;
      for (int i = 0; i < n_act; ++i) {
        acc += probs_(i);
        if (u < acc) {
          action_ = i;
          break;
        }
      }
    }
    if (buf_ != nullptr && decision_ < buf_->capacity) {
      size_t d = static_cast<size_t>(decision_);
      if (buf_->features != nullptr)
        for (int k = 0; k < POURSIM_N_FEATURES; ++k) buf_->features[d * POURSIM_N_FEATURES + static_cast<size_t>(k)] = x(k);
      if (buf_->actions != nullptr) buf_->actions[d] = action_;
      if (buf_->rewards != nullptr) buf_->rewards[d] = 0.0;
      if (buf_->probs != nullptr)
        for (int k = 0; k < n_act; ++k) buf_->probs[d * static_cast<size_t>(n_act) + static_cast<size_t>(k)] = probs_(k);
    }
  }

  const poursim_policy_t *p_;
  const poursim_rollout_buffers_t *buf_;
  Eigen::Map<const RowMatrix> W_;
  Eigen::VectorXd probs_;
  poursim::Rng rng_{0};
  int action_ = 0, decision_ = -1, reversals_ = 0, t_ = 0;
};

} // namespace

extern "C" int poursim_rollout(poursim_world_t *world, const poursim_policy_t *policy, uint32_t seed,
                               const poursim_rollout_buffers_t *buf, poursim_episode_t *ep) {
  if (world == nullptr || ep == nullptr) return POURSIM_EINVAL;
  int rc = validate_policy(policy, nullptr, 0);
  if (rc != POURSIM_OK) return rc;
  RolloutPolicy ctl(policy, *poursim_world_config(world), buf);
  const poursim::Episode e = poursim::run_episode(world, ctl, seed, policy->reward, nullptr, &ctl);
  if (!e.error.empty()) return e.status;
  *ep = e.m;
  ep->n_decisions = ctl.decisions();
  return POURSIM_OK;
}

extern "C" int poursim_rollout_batch(const poursim_config_t *config, const poursim_policy_t *policy,
                                     const uint32_t *seeds, int n, int n_threads,
                                     const poursim_rollout_buffers_t *bufs, poursim_episode_t *episodes, char *err,
                                     size_t err_len) {
  if (seeds == nullptr || episodes == nullptr || n < 0)
    return set_error(err, err_len, POURSIM_EINVAL, "rollout_batch: NULL seeds/episodes or n < 0");
  int rc = poursim_config_validate(config, err, err_len);
  if (rc != POURSIM_OK) return rc;
  rc = validate_policy(policy, err, err_len);
  if (rc != POURSIM_OK) return rc;
  if (n_threads < 1 || n_threads > 64)
    return set_error(err, err_len, POURSIM_EINVAL, "rollout_batch: n_threads %d outside 1..64", n_threads);
  n_threads = std::min(n_threads, std::max(n, 1));
  std::atomic<int> next{0};
  std::atomic<int> failed{POURSIM_OK};
  auto worker = [&]() {
    poursim_world_t *w = poursim::create_unset(config, nullptr, 0); // each rollout resets it
    if (w == nullptr) {
      failed = POURSIM_ESTATE;
      return;
    }
    for (int i = next++; i < n; i = next++) {
      int r = poursim_rollout(w, policy, seeds[i], bufs != nullptr ? &bufs[i] : nullptr, &episodes[i]);
      if (r != POURSIM_OK) failed = r;
    }
    poursim_destroy(w);
  };
  std::vector<std::thread> threads;
  for (int k = 1; k < n_threads; ++k) threads.emplace_back(worker);
  worker();
  for (std::thread &t : threads) t.join();
  if (failed != POURSIM_OK) return set_error(err, err_len, failed, "rollout_batch: an episode failed");
  return POURSIM_OK;
}
