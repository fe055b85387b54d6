// SPDX-License-Identifier: MIT
// What host_sim prints of its episodes: a line per episode, and the summary over them (text or JSON).
#ifndef POURSIM_SUMMARY_HPP
#define POURSIM_SUMMARY_HPP

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "episode_run.hpp"
#include "poursim/poursim.h"

namespace poursim {

// The line of a finished episode, number k (from 1).
void print_episode(std::FILE *f, int k, const Episode &e);

// The summary over finished episodes (at least one): one text line, or with json one JSON object with the
// controller's name (through json_quote), the first seed, tau_max [N·m], the means and each episode's figures.
// drive (the full drive's figures of each episode, drive = 1; else null): in the JSON, a "drive" object in the
// summary (the worst over the episodes) and in each episode, with the drive's faults by name.
void print_summary(std::FILE *f, bool json, const std::string &controller, uint32_t seed0, double tau_max,
                   const std::vector<Episode> &eps, const std::vector<poursim_drive_telemetry_t> *drive = nullptr);

// The full drive's worst over episodes: the largest peak current and bus voltage, the lowest bus voltage,
// every fault and limit latched in any of them.
poursim_drive_telemetry_t drive_worst(const std::vector<poursim_drive_telemetry_t> &drive);

// The names of the bits set in a fault word, lowest first, joined by sep: the core's (pour_fault_name) or
// the drive's (pour_drive_fault_name); a bit without a name as its hex value; "none" for 0.
std::string core_fault_names(uint32_t faults, const char *sep = ",");
std::string drive_fault_names(uint32_t faults, const char *sep = ",");

} // namespace poursim

#endif // POURSIM_SUMMARY_HPP
