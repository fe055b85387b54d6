// SPDX-License-Identifier: MIT
// The world's state (private to libpoursim).
#ifndef POURSIM_WORLD_HPP
#define POURSIM_WORLD_HPP

#include <box2d/box2d.h>

#include <cstdint>
#include <vector>

#include "fluid.hpp"
#include "poursim/poursim.h"

struct poursim_world {
  poursim_config_t cfg{};
  bool has_world = false;
  b2WorldId world{};
  b2BodyId ground{}, bucket{};
  b2JointId joint{};
  std::vector<b2BodyId> circles;
  std::vector<float> radii;   // [m]
  poursim::Fluid fluid;
  std::vector<double> fx, fy, fvx, fvy; // the fluid layer's view of the circles (SoA) [m], [m/s]
  std::vector<float> pos;     // x, y interleaved after the last measure [m]
  std::vector<uint8_t> region; // 0 rotating, 1 target, 2 spilled, 3 in flight
  poursim_obs_t obs{};
  uint32_t step = 0;
  uint64_t hash = 0;
  double max_wall_pen = 0.0;   // [m]
  bool brake = false;          // holding brake engaged
  char error[POURSIM_ERR_LEN] = ""; // why the last step failed
};

#endif // POURSIM_WORLD_HPP
