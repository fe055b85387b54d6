// SPDX-License-Identifier: MIT
// The world's state (private to libpoursim).
#ifndef POURSIM_WORLD_HPP
#define POURSIM_WORLD_HPP

#include <box2d/box2d.h>

#include <cstdint>
#include <vector>

#include "drive.hpp"
#include "fluid.hpp"
#include "poursim/poursim.h"
#include "rig_sensors.hpp"

struct poursim_world {
  poursim_config_t cfg{}; // as created
  poursim_config_t ep{};  // this episode's: cfg with the reset seed's rand_* draws (physics uses this)
  bool has_world = false;
  b2WorldId world{};
  b2BodyId ground{}, target{}, bucket{}; // target: the target bucket, a static body of its own (its scale)
  b2ShapeId target_shapes[3]{};          // its three boxes
  b2JointId joint{};
  std::vector<b2BodyId> circles;
  std::vector<float> radii;   // [m]
  poursim::Fluid fluid;
  // The circles as Box2D left them after the last step, read once a step (read_circles): positions [m] and
  // velocities [m/s]; the fluid layer changes the velocities before the next step.
  std::vector<double> fx, fy, fvx, fvy;
  std::vector<uint8_t> region; // 0 rotating, 1 target, 2 spilled, 3 in flight
  poursim_obs_t obs{};
  uint32_t step = 0;
  uint64_t hash = 0;
  double max_wall_pen = 0.0;   // [m]
  bool brake = false;          // holding brake engaged
  poursim::Drive drive;
  double bucket_mass_kg = 0.0; // the empty rotating bucket's mass as Box2D has it (the rotating cell's tare)
  poursim::Gauss sensor_noise; // the load cells' noise, a stream of its own
  poursim::LoadCell scale_rotating, scale_target;
  std::vector<b2ContactData> contacts; // scratch for the target's contacts
  char error[POURSIM_ERR_LEN] = ""; // why the last step failed
};

namespace poursim {

// For the drive checks (checks.cpp): takes the liquid out of the scene (the empty bucket), and with
// free_spin also the joint's stops, so that the bucket can turn for good.
void empty_bucket(poursim_world_t *w, bool free_spin);

// A world with its config and no scene yet (poursim_create without its reset): only poursim_reset and
// poursim_destroy may be called on it. For callers that reset it at once with their own seed.
poursim_world_t *create_unset(const poursim_config_t *config, char *err, size_t err_len);

} // namespace poursim

#endif // POURSIM_WORLD_HPP
