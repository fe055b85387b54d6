// SPDX-License-Identifier: MIT
// What host_sim prints of its episodes: a line per episode, and the summary over them (text or JSON).
#ifndef POURSIM_SUMMARY_HPP
#define POURSIM_SUMMARY_HPP

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "episode_run.hpp"

namespace poursim {

// The line of a finished episode, number k (from 1).
void print_episode(std::FILE *f, int k, const Episode &e);

// The summary over finished episodes (at least one): one text line, or with json one JSON object with the
// controller's name (through json_quote), the first seed, tau_max [N·m], the means and each episode's figures.
void print_summary(std::FILE *f, bool json, const std::string &controller, uint32_t seed0, double tau_max,
                   const std::vector<Episode> &eps);

} // namespace poursim

#endif // POURSIM_SUMMARY_HPP
