// SPDX-License-Identifier: MIT
// The sizes of the plain records Python mirrors in ctypes, so that a test can hold each mirror to C's.
#include <cstring>

#include "poursim/checks.h"
#include "poursim/poursim.h"
#include "poursim/weights_file.h"

extern "C" size_t poursim_sizeof(const char *type_name) {
  static const struct {
    const char *name;
    size_t size;
  } kTypes[] = {
      {"poursim_obs_t", sizeof(poursim_obs_t)},
      {"poursim_reward_t", sizeof(poursim_reward_t)},
      {"poursim_policy_t", sizeof(poursim_policy_t)},
      {"poursim_rollout_buffers_t", sizeof(poursim_rollout_buffers_t)},
      {"poursim_episode_t", sizeof(poursim_episode_t)},
      {"poursim_retention_t", sizeof(poursim_retention_t)},
      {"poursim_slosh_t", sizeof(poursim_slosh_t)},
      {"poursim_drive_check_t", sizeof(poursim_drive_check_t)},
      {"poursim_sensor_check_t", sizeof(poursim_sensor_check_t)},
      {"poursim_weights_file_t", sizeof(poursim_weights_file_t)},
  };
  if (type_name == nullptr) return 0;
  for (const auto &t : kTypes)
    if (std::strcmp(t.name, type_name) == 0) return t.size;
  return 0;
}
