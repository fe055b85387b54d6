// SPDX-License-Identifier: MIT
#include "episode_run.hpp"

#include <utility>

#include "controllers.hpp"

namespace poursim {

namespace {

// Why a world call failed: the world's own message, or the status where it left none (a refused argument).
std::string world_failure(const poursim_world_t *world, const char *call, int status) {
  const char *why = poursim_world_error(world);
  if (why != nullptr && *why != '\0') return why;
  return std::string(call) + " refused with status " + std::to_string(status);
}

} // namespace

void EpisodeRun::keep_frame() {
  std::vector<float> xy(static_cast<size_t>(2 * n_particles_));
  poursim_particles(world_, xy.data(), nullptr, n_particles_);
  rec_->frames.push_back(std::move(xy));
  rec_->frame_theta.push_back(obs_.theta);
  rec_->frame_t.push_back(obs_.t);
}

bool EpisodeRun::begin(uint32_t seed) {
  e_ = Episode{};
  e_.seed = seed;
  fault_step_ = -1;
  int rc = poursim_reset(world_, seed);
  if (rc != POURSIM_OK) {
    e_.error = world_failure(world_, "poursim_reset", rc);
    e_.status = rc;
    return false;
  }
  ctl_.set_rig(*poursim_episode_config(world_));
  ctl_.reset(seed);
  tau_max_ = poursim_world_config(world_)->tau_max;
  n_particles_ = poursim_particle_count(world_);
  poursim_observe(world_, &obs_);
  meter_.reset(*poursim_episode_config(world_), reward_, obs_);
  if (rec_ != nullptr && rec_->frame_every > 0) {
    rec_->radius.assign(static_cast<size_t>(n_particles_), 0.0f);
    poursim_particles(world_, nullptr, rec_->radius.data(), n_particles_);
    keep_frame();
  }
  return true;
}

bool EpisodeRun::tick() {
  const double a = ctl_.command(obs_);
  if (ctl_.failed()) {
    e_.error = ctl_.failure();
    e_.status = POURSIM_ESTATE;
    return false;
  }
  if (fault_step_ < 0 && ctl_.faults() != 0) fault_step_ = static_cast<int>(obs_.step);
  int rc = poursim_set_brake(world_, ctl_.brake() ? 1 : 0);
  if (rc == POURSIM_OK) rc = poursim_step(world_, a, &obs_);
  if (rc != POURSIM_OK) {
    e_.error = world_failure(world_, "poursim_step", rc);
    e_.status = rc;
    return false;
  }
  meter_.add(obs_, a * tau_max_);
  if (hook_ != nullptr) hook_->after_step(obs_, a, meter_);
  if (rec_ != nullptr) {
    if (rec_->steps) rec_->samples.push_back({obs_, ctl_.action(), meter_.last_reward()});
    if (rec_->frame_every > 0 && obs_.step % static_cast<uint32_t>(rec_->frame_every) == 0) keep_frame();
  }
  return true;
}

const Episode &EpisodeRun::finish() {
  e_.m = meter_.result();
  e_.m.faults = ctl_.faults();
  e_.m.fault_step = fault_step_;
  return e_;
}

Episode run_episode(poursim_world_t *world, Controller &ctl, uint32_t seed, const poursim_reward_t &reward,
                    Recorder *rec, StepHook *hook) {
  EpisodeRun run(world, ctl, reward, rec, hook);
  if (!run.begin(seed)) return run.episode();
  while (!run.done())
    if (!run.tick()) return run.episode();
  return run.finish();
}

} // namespace poursim
