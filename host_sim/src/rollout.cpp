// SPDX-License-Identifier: MIT
// Whole episodes in C for the trainer: a float softmax-linear policy decides every P steps, its torque
// passes through the firmware's own safety envelope, and the arrays Python asked for are filled.
#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

extern "C" {
#include "pour/safety.h"
}
#include "poursim/poursim.h"
#include "poursim_internal.hpp"

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
  return POURSIM_OK;
}

double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

// The features of the weights.h spec, from the physical state (not the world's own normalisation).
Features features_of(const poursim_policy_t *p, const poursim_obs_t &o) {
  Features x;
  x << clamp01((o.theta - p->theta_min) / (p->theta_max - p->theta_min)),
      clamp01((o.omega + p->omega_max) / (2.0 * p->omega_max)), clamp01(o.v_rotating), clamp01(o.v_target),
      clamp01(o.v_spill), 1.0;
  return x;
}

// Torque fraction → Q15 for the envelope: round to nearest, saturate.
q15_t to_q15(double a) {
  double q = std::nearbyint(a * 32768.0);
  return static_cast<q15_t>(std::max(-32768.0, std::min(32767.0, q)));
}

} // namespace

extern "C" int poursim_rollout(poursim_world_t *world, const poursim_policy_t *policy, uint32_t seed,
                               const poursim_rollout_buffers_t *buf, poursim_episode_t *ep) {
  if (world == nullptr || ep == nullptr) return POURSIM_EINVAL;
  int rc = validate_policy(policy, nullptr, 0);
  if (rc != POURSIM_OK) return rc;
  const poursim_config_t *cfg = poursim_world_config(world);
  rc = poursim_reset(world, seed);
  if (rc != POURSIM_OK) return rc;

  pour_safety_config_t scfg = pour_safety_default_config();
  pour_safety_t safety;
  if (pour_safety_init(&safety, &scfg) != POUR_OK) return POURSIM_ESTATE;

  const int n_act = policy->n_actions;
  Eigen::Map<const RowMatrix> W(policy->w, POURSIM_N_FEATURES, n_act);
  // Sampling draws from its own stream so that greedy and sampled runs share the liquid of a seed.
  poursim::Rng rng(0xA5A5A5A5ULL ^ (static_cast<unsigned long long>(seed) * 0x100000001B3ULL));
  const int n_steps = static_cast<int>(std::lround(cfg->episode_s / cfg->dt));
  std::vector<double> settled(static_cast<size_t>(n_steps));

  std::memset(ep, 0, sizeof *ep);
  poursim_obs_t o;
  poursim_observe(world, &o);
  int action = 0, decision = -1;
  double disc = 1.0, ret = 0.0, sum = 0.0, max_theta = o.theta;
  Eigen::VectorXd probs(n_act);
  for (int t = 0; t < n_steps; ++t) {
    if (t % policy->decision_period == 0) {
      ++decision;
      Features x = features_of(policy, o);
      Eigen::VectorXd logits = (x * W).transpose();
      probs = (logits.array() - logits.maxCoeff()).exp();
      probs /= probs.sum();
      if (policy->greedy) {
        Eigen::Index best = 0;
        logits.maxCoeff(&best); // first maximum: ties go to the lowest index
        action = static_cast<int>(best);
      } else {
        double u = rng.uniform(), acc = 0.0;
        action = n_act - 1;
        for (int i = 0; i < n_act; ++i) {
          acc += probs(i);
          if (u < acc) {
            action = i;
            break;
          }
        }
      }
      if (buf != nullptr && decision < buf->capacity) {
        size_t d = static_cast<size_t>(decision);
        if (buf->features != nullptr)
          for (int k = 0; k < POURSIM_N_FEATURES; ++k) buf->features[d * POURSIM_N_FEATURES + static_cast<size_t>(k)] = x(k);
        if (buf->actions != nullptr) buf->actions[d] = action;
        if (buf->rewards != nullptr) buf->rewards[d] = 0.0;
        if (buf->probs != nullptr)
          for (int k = 0; k < n_act; ++k) buf->probs[d * static_cast<size_t>(n_act) + static_cast<size_t>(k)] = probs(k);
      }
    }
    int32_t theta_urad = static_cast<int32_t>(std::max(-2.0e9, std::min(2.0e9, std::round(o.theta * 1e6))));
    q15_t cmd = pour_safety_apply(&safety, to_q15(policy->levels[action]), theta_urad);
    rc = poursim_step(world, cmd / 32768.0, &o);
    if (rc != POURSIM_OK) return rc;
    ret += disc * o.reward;
    disc *= cfg->gamma;
    sum += o.reward;
    max_theta = std::max(max_theta, o.theta);
    settled[static_cast<size_t>(t)] = o.v_target + o.v_spill;
    if (buf != nullptr) {
      if (decision < buf->capacity && buf->rewards != nullptr) buf->rewards[decision] += o.reward;
      if (t < buf->step_capacity) {
        if (buf->step_rewards != nullptr) buf->step_rewards[t] = o.reward;
        if (buf->step_theta != nullptr) buf->step_theta[t] = o.theta;
      }
    }
  }
  ep->n_steps = n_steps;
  ep->n_decisions = decision + 1;
  ep->poured = o.v_target;
  ep->spilled = o.v_spill;
  ep->remaining = o.v_rotating;
  ep->ret = ret;
  ep->reward_sum = sum;
  ep->max_theta = max_theta;
  ep->finish_time = -1.0;
  double final_settled = n_steps > 0 ? settled.back() : 0.0;
  if (final_settled >= 0.01) {
    for (int t = 0; t < n_steps; ++t) {
      if (settled[static_cast<size_t>(t)] >= 0.99 * final_settled) {
        ep->finish_time = (t + 1) * cfg->dt;
        break;
      }
    }
  }
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
    poursim_world_t *w = poursim_create(config, nullptr, 0);
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
