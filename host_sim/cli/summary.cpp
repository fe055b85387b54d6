// SPDX-License-Identifier: MIT
#include "summary.hpp"

#include <algorithm>

#include "outputs.hpp"
#include "stats.hpp"

extern "C" {
#include "pour/drive_faults.h"
#include "pour/faults.h"
}

namespace poursim {

namespace {

template <typename NameOf> std::string names(uint32_t faults, const char *sep, NameOf name_of) {
  if (faults == 0) return "none";
  std::string out;
  for (unsigned i = 0; i < 32; ++i) {
    const uint32_t bit = 1u << i;
    if ((faults & bit) == 0) continue;
    const char *n = name_of(bit);
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%x", static_cast<unsigned>(bit));
    if (!out.empty()) out += sep;
    out += n != nullptr ? n : hex;
  }
  return out;
}

// A fault word as a JSON array of names.
template <typename NameOf> std::string json_names(uint32_t faults, NameOf name_of) {
  if (faults == 0) return "[]";
  return "[\"" + names(faults, "\", \"", name_of) + "\"]";
}

const char *core_name(uint32_t bit) { return bit > 0xFFFFu ? nullptr : pour_fault_name(static_cast<uint16_t>(bit)); }

std::string json_drive(const poursim_drive_telemetry_t &d) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "{\"peak_current_a\": %.3f, \"peak_vbus_v\": %.3f, \"min_vbus_v\": %.3f, "
                "\"faults\": ", d.peak_current, d.peak_vbus, d.min_vbus);
  return buf + json_names(d.faults, pour_drive_fault_name) + "}";
}

} // namespace

std::string core_fault_names(uint32_t faults, const char *sep) { return names(faults, sep, core_name); }

std::string drive_fault_names(uint32_t faults, const char *sep) { return names(faults, sep, pour_drive_fault_name); }

poursim_drive_telemetry_t drive_worst(const std::vector<poursim_drive_telemetry_t> &drive) {
  poursim_drive_telemetry_t w{};
  for (size_t k = 0; k < drive.size(); ++k) {
    w.peak_current = std::max(w.peak_current, drive[k].peak_current);
    w.peak_vbus = std::max(w.peak_vbus, drive[k].peak_vbus);
    w.min_vbus = k == 0 ? drive[k].min_vbus : std::min(w.min_vbus, drive[k].min_vbus);
    w.faults |= drive[k].faults;
    w.limits |= drive[k].limits;
  }
  return w;
}

void print_episode(std::FILE *f, int k, const Episode &e) {
  std::fprintf(f,
               "episode %d seed %u: poured %5.1f %% (%5.2f L)  spilled %4.1f %% (%4.2f L)  left %4.1f %%  finish %s"
               "  peak %.2f rad/s %.0f rad/s²  reversals %d  return %.1f\n",
               k, e.seed, 100 * e.m.poured, e.m.poured * e.m.liquid_l, 100 * e.m.spilled, e.m.spilled * e.m.liquid_l,
               100 * e.m.remaining,
               e.m.finish_time < 0 ? "  -   " : (std::to_string(e.m.finish_time).substr(0, 5) + " s").c_str(),
               e.m.peak_omega, e.m.peak_alpha, e.m.reversals, e.m.ret);
  if (e.m.faults != 0)
    std::fprintf(f, "episode %d seed %u: the core faulted (%s) at step %d: controlled stop, then the brake\n", k,
                 e.seed, core_fault_names(static_cast<uint32_t>(e.m.faults)).c_str(), e.m.fault_step);
}

void print_summary(std::FILE *f, bool json, const std::string &controller, uint32_t seed0, double tau_max,
                   const std::vector<Episode> &eps, const std::vector<poursim_drive_telemetry_t> *drive) {
  const int episodes = static_cast<int>(eps.size());
  std::vector<double> poured, spilled, poured_l, spilled_l, finish, ret, peak_omega, peak_alpha, reversals;
  int unfinished = 0, faulted = 0;
  for (const Episode &e : eps) {
    if (e.m.faults != 0) ++faulted;
    poured.push_back(100 * e.m.poured);
    spilled.push_back(100 * e.m.spilled);
    poured_l.push_back(e.m.poured * e.m.liquid_l);
    spilled_l.push_back(e.m.spilled * e.m.liquid_l);
    ret.push_back(e.m.ret);
    peak_omega.push_back(e.m.peak_omega);
    peak_alpha.push_back(e.m.peak_alpha);
    reversals.push_back(e.m.reversals);
    if (e.m.finish_time >= 0) finish.push_back(e.m.finish_time);
    else ++unfinished;
  }
  const double max_finish = finish.empty() ? -1.0 : *std::max_element(finish.begin(), finish.end());
  const double max_peak = peak_omega.empty() ? 0.0 : *std::max_element(peak_omega.begin(), peak_omega.end());
  if (json) {
    std::fprintf(f,
                 "{\"controller\": %s, \"episodes\": %d, \"seed\": %u, \"tau_max_nm\": %.4f, "
                 "\"poured_pct\": %.3f, \"poured_pct_std\": %.3f, \"spilled_pct\": %.3f, \"spilled_pct_std\": %.3f, "
                 "\"poured_l\": %.4f, \"spilled_l\": %.4f, \"finish_s\": %.4f, \"finish_max_s\": %.4f, "
                 "\"unfinished\": %d, \"peak_omega_rad_s\": %.4f, \"peak_omega_max_rad_s\": %.4f, "
                 "\"peak_alpha_rad_s2\": %.3f, \"reversals\": %.2f, \"return\": %.4f, \"return_std\": %.4f, "
                 "\"faulted\": %d, ",
                 json_quote(controller).c_str(), episodes, seed0, tau_max, mean(poured), stdev(poured), mean(spilled),
                 stdev(spilled), mean(poured_l), mean(spilled_l), finish.empty() ? -1.0 : mean(finish), max_finish,
                 unfinished, mean(peak_omega), max_peak, mean(peak_alpha), mean(reversals), mean(ret), stdev(ret),
                 faulted);
    if (drive != nullptr) std::fprintf(f, "\"drive\": %s, ", json_drive(drive_worst(*drive)).c_str());
    std::fprintf(f, "\"per_episode\": [");
    for (size_t k = 0; k < eps.size(); ++k) {
      const Episode &e = eps[k];
      std::fprintf(f,
                   "%s{\"seed\": %u, \"poured_pct\": %.3f, \"spilled_pct\": %.3f, \"liquid_l\": %.4f, "
                   "\"finish_s\": %.4f, \"peak_omega_rad_s\": %.4f, \"peak_alpha_rad_s2\": %.3f, \"reversals\": %d, "
                   "\"return\": %.4f, \"faults\": %d, \"fault_names\": %s, \"fault_step\": %d",
                   k ? ", " : "", e.seed, 100 * e.m.poured, 100 * e.m.spilled, e.m.liquid_l, e.m.finish_time,
                   e.m.peak_omega, e.m.peak_alpha, e.m.reversals, e.m.ret, e.m.faults,
                   json_names(static_cast<uint32_t>(e.m.faults), core_name).c_str(), e.m.fault_step);
      if (drive != nullptr && k < drive->size()) std::fprintf(f, ", \"drive\": %s", json_drive((*drive)[k]).c_str());
      std::fprintf(f, "}");
    }
    std::fprintf(f, "]}\n");
  } else {
    std::fprintf(f,
                 "summary (%d episode%s): poured %.1f %% (%.2f L, sd %.1f %%)  spilled %.1f %% (%.2f L, sd %.1f %%)  "
                 "finish %s (max %s)  peak %.2f rad/s (max %.2f)  %.0f rad/s²  reversals %.1f  return %.1f\n",
                 episodes, episodes > 1 ? "s" : "", mean(poured), mean(poured_l), stdev(poured), mean(spilled),
                 mean(spilled_l), stdev(spilled),
                 finish.empty() ? "-" : (std::to_string(mean(finish)).substr(0, 5) + " s").c_str(),
                 finish.empty() ? "-" : (std::to_string(max_finish).substr(0, 5) + " s").c_str(), mean(peak_omega),
                 max_peak, mean(peak_alpha), mean(reversals), mean(ret));
    if (faulted > 0) std::fprintf(f, "the core faulted in %d of %d episodes\n", faulted, episodes);
  }
}

} // namespace poursim
