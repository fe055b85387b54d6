// SPDX-License-Identifier: MIT
// One episode in the world, driven by a Controller: its figures (EpisodeMeter) and, on request, every step
// and frames of the liquid for the CSV and the renderer (outputs.hpp writes them).
#ifndef POURSIM_EPISODE_RUN_HPP
#define POURSIM_EPISODE_RUN_HPP

#include <cstdint>
#include <string>
#include <vector>

#include "poursim/poursim.h"

namespace poursim {

class Controller; // controllers.hpp

// One step of history: the observation a step produced and the policy's action in force for it (-1 for
// baselines).
struct Sample {
  poursim_obs_t obs;
  int action;
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

struct Episode {
  uint32_t seed = 0;
  poursim_episode_t m{}; // the figures (metrics.hpp); valid only when error is empty
  std::string error;     // why the episode stopped early (the controller's or the world's failure), else empty
};

// Resets world and controller to seed and steps until the episode is done, or until the controller fails
// or a step is refused (the error then says why). rec (may be null) receives what it asks for.
Episode run_episode(poursim_world_t *world, Controller &ctl, uint32_t seed, Recorder *rec);

} // namespace poursim

#endif // POURSIM_EPISODE_RUN_HPP
