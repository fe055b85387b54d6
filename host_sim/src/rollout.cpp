// SPDX-License-Identifier: MIT
// Whole episodes in C for the trainer: a float softmax-linear policy decides every P steps on the state the
// firmware's own estimator makes of the rig's sensors, its torque passes through the firmware's own safety
// envelope (the motion envelope included), and the arrays Python asked for are filled.
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
#include "pour/safety.h"
#include "pour/sensors.h"
}
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
  return POURSIM_OK;
}

double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

// The features of the weights.h spec, from the state the firmware's estimator makes of the sensors.
Features features_of(const poursim_policy_t *p, const pour_state_t &s) {
  const double theta = s.theta_urad * 1e-6, omega = s.omega_urad_s * 1e-6;
  Features x;
  x << clamp01((theta - p->theta_min) / (p->theta_max - p->theta_min)),
      clamp01((omega + p->omega_max) / (2.0 * p->omega_max)), clamp01(s.v_rotating / 32768.0),
      clamp01(s.v_target / 32768.0), clamp01(s.v_spill / 32768.0), 1.0;
  return x;
}

} // namespace

extern "C" int16_t poursim_fraction_to_q15(double fraction) {
  if (std::isnan(fraction)) return 0;
  const double q = std::floor(fraction * 32768.0 + 0.5); // half up, as the firmware rounds
  return static_cast<int16_t>(q < -32768.0 ? -32768.0 : (q > 32767.0 ? 32767.0 : q));
}

extern "C" int poursim_rollout(poursim_world_t *world, const poursim_policy_t *policy, uint32_t seed,
                               const poursim_rollout_buffers_t *buf, poursim_episode_t *ep) {
  if (world == nullptr || ep == nullptr) return POURSIM_EINVAL;
  int rc = validate_policy(policy, nullptr, 0);
  if (rc != POURSIM_OK) return rc;
  const poursim_config_t *cfg = poursim_world_config(world);
  rc = poursim_reset(world, seed);
  if (rc != POURSIM_OK) return rc;

  // The firmware's defaults, as the shipped controller runs them; the encoder as the rig has it.
  pour_control_config_t fw = pour_control_default_config();
  fw.sensors.encoder_bits = static_cast<uint8_t>(cfg->encoder_bits);
  pour_safety_t safety;
  pour_estimator_t est;
  if (pour_safety_init(&safety, &fw.safety) != POUR_OK || pour_estimator_init(&est, &fw.sensors) != POUR_OK)
    return POURSIM_ESTATE;

  const int n_act = policy->n_actions;
  Eigen::Map<const RowMatrix> W(policy->w, POURSIM_N_FEATURES, n_act);
  // Sampling draws from its own stream so that greedy and sampled runs share the liquid of a seed.
  poursim::Rng rng(0xA5A5A5A5ULL ^ (static_cast<unsigned long long>(seed) * 0x100000001B3ULL));
  const int n_steps = static_cast<int>(std::lround(cfg->episode_s / cfg->dt));

  poursim_obs_t o;
  poursim_observe(world, &o);
  poursim::EpisodeMeter meter;
  meter.reset(*poursim_episode_config(world), o);
  pour_state_t state{};
  int action = 0, decision = -1, reversals = 0;
  Eigen::VectorXd probs(n_act);
  for (int t = 0; t < n_steps; ++t) {
    // A sample the estimator refuses (the firmware would fault) leaves the last state in place.
    const pour_sensors_t sample = {static_cast<uint32_t>(t), o.encoder, o.scale_rotating_g, o.scale_target_g};
    pour_estimator_update(&est, &sample, &state);
    if (t % policy->decision_period == 0) {
      ++decision;
      Features x = features_of(policy, state);
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
    q15_t cmd = pour_safety_apply(&safety, poursim_fraction_to_q15(policy->levels[action]), state.theta_urad, state.omega_urad_s);
    rc = poursim_step(world, cmd / 32768.0, &o);
    if (rc != POURSIM_OK) return rc;
    meter.add(o, cmd / 32768.0 * cfg->tau_max);
    // Training's reward shaping: each torque reversal costs k_reversal (0: the world's reward as it is).
    const int new_reversals = meter.reversals() - reversals;
    reversals += new_reversals;
    const double r = o.reward - policy->k_reversal * new_reversals;
    if (buf != nullptr) {
      if (decision < buf->capacity && buf->rewards != nullptr) buf->rewards[decision] += r;
      if (t < buf->step_capacity) {
        if (buf->step_rewards != nullptr) buf->step_rewards[t] = r;
        if (buf->step_theta != nullptr) buf->step_theta[t] = o.theta;
      }
    }
  }
  *ep = meter.result();
  ep->n_decisions = decision + 1;
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
