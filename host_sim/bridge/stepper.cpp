// SPDX-License-Identifier: MIT
// poursim_stepper_*: the Gymnasium environment's episodes through EpisodeRun (episode_run.hpp), the tick
// driver and meter of every other episode, with each due decision requested from outside.
#include "poursim/stepper.h"

#include <cmath>
#include <new>
#include <string>

extern "C" {
#include "pour/control.h"
}
#include "controllers.hpp"
#include "episode_run.hpp"
#include "poursim_internal.hpp"

using poursim::set_error;

namespace {

// The firmware's pipeline with decisions from outside: the action and level of the latest advance.
class ExternalController : public poursim::CoreController {
 public:
  ExternalController(const poursim_config_t &sim, int period) : CoreController(sim), period_(period) {}
  std::string name() const override { return "stepper"; }
  void set_request(int action, double level) {
    action_ = action;
    level_ = level;
  }

 protected:
  pour_status_t init(pour_control_t *ctl, const pour_control_config_t &config, uint32_t) override {
    return pour_control_init_external(ctl, &config, static_cast<uint16_t>(period_));
  }
  void decide(pour_control_t *ctl, const pour_state_t &) override {
    pour_control_request(ctl, static_cast<uint8_t>(action_), poursim_fraction_to_q15(level_));
  }

 private:
  int period_, action_ = 0;
  double level_ = 0.0;
};

} // namespace

struct poursim_stepper {
  poursim_stepper(poursim_world_t *w, const poursim_reward_t &r, int period)
      : ctl(*poursim_world_config(w), period), run(w, ctl, r) {}
  ExternalController ctl;
  poursim::EpisodeRun run;
  bool started = false;
};

extern "C" poursim_stepper_t *poursim_stepper_create(poursim_world_t *world, const poursim_reward_t *reward,
                                                     int decision_period, char *err, size_t err_len) {
  if (world == nullptr) {
    set_error(err, err_len, POURSIM_EINVAL, "stepper: world is NULL");
    return nullptr;
  }
  if (poursim_reward_validate(reward, err, err_len) != POURSIM_OK) return nullptr;
  if (decision_period < 1 || decision_period > 65535) {
    set_error(err, err_len, POURSIM_EINVAL, "stepper: decision_period %d outside 1..65535", decision_period);
    return nullptr;
  }
  poursim_stepper_t *s = new (std::nothrow) poursim_stepper(world, *reward, decision_period);
  if (s == nullptr) set_error(err, err_len, POURSIM_ESTATE, "stepper: out of memory");
  return s;
}

extern "C" void poursim_stepper_destroy(poursim_stepper_t *s) { delete s; }

namespace {

int failed(poursim_stepper_t *s, char *err, size_t err_len) {
  const poursim::Episode &e = s->run.episode();
  return set_error(err, err_len, e.status, "%s", e.error.c_str());
}

} // namespace

extern "C" int poursim_stepper_reset(poursim_stepper_t *s, uint32_t seed, char *err, size_t err_len) {
  if (s == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "stepper is NULL");
  s->started = false;
  if (!s->run.begin(seed)) return failed(s, err, err_len);
  if (s->ctl.failed()) return set_error(err, err_len, POURSIM_ESTATE, "%s", s->ctl.failure().c_str());
  s->ctl.sense(s->run.obs()); // the state of the latest step is there to read before the next decision
  s->started = true;
  return POURSIM_OK;
}

extern "C" int poursim_stepper_advance(poursim_stepper_t *s, int action, double level, int ticks, double *reward,
                                       int16_t *commands, char *err, size_t err_len) {
  if (s == nullptr || !s->started)
    return set_error(err, err_len, POURSIM_ESTATE, "stepper: reset it first (or after its failure)");
  if (ticks < 0 || action < 0 || action > 255 || std::isnan(level))
    return set_error(err, err_len, POURSIM_EINVAL, "stepper: action %d, level %g, ticks %d", action, level, ticks);
  s->ctl.set_request(action, level);
  double sum = 0.0;
  for (int k = 0; k < ticks; ++k) {
    if (!s->run.tick()) {
      s->started = false;
      return failed(s, err, err_len);
    }
    sum += s->run.meter().last_reward();
    if (commands != nullptr) commands[k] = s->ctl.output().torque;
    s->ctl.sense(s->run.obs());
  }
  if (reward != nullptr) *reward = sum;
  return POURSIM_OK;
}

extern "C" void poursim_stepper_obs(const poursim_stepper_t *s, poursim_obs_t *obs) {
  if (s != nullptr && obs != nullptr) *obs = s->run.obs();
}

extern "C" void poursim_stepper_state(const poursim_stepper_t *s, pour_state_t *state) {
  if (s != nullptr && state != nullptr) *state = *pour_control_state(&s->ctl.core());
}

extern "C" int poursim_stepper_faults(const poursim_stepper_t *s) { return s != nullptr ? s->ctl.faults() : 0; }

extern "C" void poursim_stepper_episode(poursim_stepper_t *s, poursim_episode_t *episode) {
  if (s != nullptr && episode != nullptr) *episode = s->run.finish().m;
}
