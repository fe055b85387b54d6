// SPDX-License-Identifier: MIT
// One episode in the world, driven by a Controller: its figures (EpisodeMeter) and, on request, every step
// and frames of the liquid for the CSV and the renderer (outputs.hpp writes them). host_sim's episodes and
// the trainer's rollouts (rollout.cpp) both run through it.
#ifndef POURSIM_EPISODE_RUN_HPP
#define POURSIM_EPISODE_RUN_HPP

#include <cstdint>
#include <string>
#include <vector>

#include "metrics.hpp"
#include "poursim/poursim.h"

namespace poursim {

class Controller; // controllers.hpp

// One step of history: the observation a step produced and the policy's action in force for it (-1 for
// baselines).
struct Sample {
  poursim_obs_t obs;
  int action;
  double reward; // of this step (poursim_reward_t)
};

// What run_episode keeps of an episode beyond its figures.
struct Recorder {
  bool steps = false;  // keep every step (CSV, render plots)
  int frame_every = 0; // keep circle positions every this many steps and at the start (render), 0 = never
  std::vector<Sample> samples;
  std::vector<std::vector<float>> frames; // x0, y0, x1, y1, ... of every circle [m]
  std::vector<double> frame_theta, frame_t; // [rad], [s]
  std::vector<float> radius; // of this episode's circles (the order is shuffled per seed) [m]
};

// Told of every step as it is made, after the meter has counted it.
class StepHook {
 public:
  virtual ~StepHook() = default;
  // obs: what the step produced; command: what it was given [fraction of tau_max]; meter: the episode so far.
  virtual void after_step(const poursim_obs_t &obs, double command, const EpisodeMeter &meter) = 0;
};

struct Episode {
  uint32_t seed = 0;
  poursim_episode_t m{}; // the figures (metrics.hpp); valid only when error is empty
  std::string error;     // why the episode stopped early (the controller's or the world's failure), else empty
  int status = POURSIM_OK; // with an error: the refused world call's status, POURSIM_ESTATE for the controller
};

// Resets world and controller to seed and steps until the observation says the episode is done, or until
// the controller fails or the world refuses a call (the error then says why); reward makes the figures'
// return. rec and hook (either may be null) receive what they ask for.
Episode run_episode(poursim_world_t *world, Controller &ctl, uint32_t seed, const poursim_reward_t &reward,
                    Recorder *rec, StepHook *hook = nullptr);

} // namespace poursim

#endif // POURSIM_EPISODE_RUN_HPP
