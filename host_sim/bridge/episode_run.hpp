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

// One episode, tick by tick: the one tick driver of host_sim's episodes, the trainer's rollouts and the
// Gymnasium stepper (poursim_stepper_*). begin() resets world and controller to seed; each tick() asks the
// controller for its command on the latest observation, applies its brake, steps the world and meters the
// step; finish() gives the figures. A false return means the controller failed or the world refused a call:
// episode() then holds the error and the status.
class EpisodeRun {
 public:
  EpisodeRun(poursim_world_t *world, Controller &ctl, const poursim_reward_t &reward, Recorder *rec = nullptr,
             StepHook *hook = nullptr)
      : world_(world), ctl_(ctl), reward_(reward), rec_(rec), hook_(hook) {}
  bool begin(uint32_t seed);
  bool tick();
  bool done() const { return obs_.done != 0; }
  const poursim_obs_t &obs() const { return obs_; }
  const EpisodeMeter &meter() const { return meter_; }
  // The figures so far (final once done), with the controller's faults and the step that first saw one.
  const Episode &finish();
  const Episode &episode() const { return e_; }

 private:
  void keep_frame();
  poursim_world_t *world_;
  Controller &ctl_;
  poursim_reward_t reward_;
  Recorder *rec_;
  StepHook *hook_;
  Episode e_;
  EpisodeMeter meter_;
  poursim_obs_t obs_{};
  double tau_max_ = 0.0;
  int n_particles_ = 0, fault_step_ = -1;
};

// Resets world and controller to seed and steps until the observation says the episode is done, or until
// the controller fails or the world refuses a call (the error then says why); reward makes the figures'
// return. rec and hook (either may be null) receive what they ask for.
Episode run_episode(poursim_world_t *world, Controller &ctl, uint32_t seed, const poursim_reward_t &reward,
                    Recorder *rec, StepHook *hook = nullptr);

} // namespace poursim

#endif // POURSIM_EPISODE_RUN_HPP
