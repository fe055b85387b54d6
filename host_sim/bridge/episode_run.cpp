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

Episode run_episode(poursim_world_t *world, Controller &ctl, uint32_t seed, const poursim_reward_t &reward,
                    Recorder *rec, StepHook *hook) {
  Episode e;
  e.seed = seed;
  int rc = poursim_reset(world, seed);
  if (rc != POURSIM_OK) {
    e.error = world_failure(world, "poursim_reset", rc);
    e.status = rc;
    return e;
  }
  ctl.set_rig(*poursim_episode_config(world));
  ctl.reset(seed);
  const poursim_config_t *cfg = poursim_world_config(world);
  const int n = poursim_particle_count(world);
  poursim_obs_t o;
  poursim_observe(world, &o);
  EpisodeMeter meter;
  meter.reset(*poursim_episode_config(world), reward, o);
  auto keep_frame = [&](const poursim_obs_t &ob) {
    std::vector<float> xy(static_cast<size_t>(2 * n));
    poursim_particles(world, xy.data(), nullptr, n);
    rec->frames.push_back(std::move(xy));
    rec->frame_theta.push_back(ob.theta);
    rec->frame_t.push_back(ob.t);
  };
  if (rec != nullptr && rec->frame_every > 0) {
    rec->radius.assign(static_cast<size_t>(n), 0.0f);
    poursim_particles(world, nullptr, rec->radius.data(), n);
    keep_frame(o);
  }
  int fault_step = -1;
  while (!o.done) {
    const double a = ctl.command(o);
    if (ctl.failed()) {
      e.error = ctl.failure();
      e.status = POURSIM_ESTATE;
      return e;
    }
    if (fault_step < 0 && ctl.faults() != 0) fault_step = static_cast<int>(o.step);
    rc = poursim_set_brake(world, ctl.brake() ? 1 : 0);
    if (rc == POURSIM_OK) rc = poursim_step(world, a, &o);
    if (rc != POURSIM_OK) {
      e.error = world_failure(world, "poursim_step", rc);
      e.status = rc;
      return e;
    }
    meter.add(o, a * cfg->tau_max);
    if (hook != nullptr) hook->after_step(o, a, meter);
    if (rec != nullptr) {
      if (rec->steps) rec->samples.push_back({o, ctl.action(), meter.last_reward()});
      if (rec->frame_every > 0 && o.step % static_cast<uint32_t>(rec->frame_every) == 0) keep_frame(o);
    }
  }
  e.m = meter.result();
  e.m.faults = ctl.faults();
  e.m.fault_step = fault_step;
  return e;
}

} // namespace poursim
