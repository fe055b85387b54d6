// SPDX-License-Identifier: MIT
// host_sim --bench: speed, contact quality, rollouts per second, and the liquid against physics.
#ifndef POURSIM_BENCH_HPP
#define POURSIM_BENCH_HPP

#include <string>

#include "poursim/poursim.h"

namespace poursim {

// Prints every figure; policy_path (may be empty) is the policy the rollouts run, else a uniform random
// one. episodes: how many timed episodes (3..10). Returns the exit status.
int run_bench(const poursim_config_t &cfg, const std::string &policy_path, int episodes);

} // namespace poursim

#endif // POURSIM_BENCH_HPP
