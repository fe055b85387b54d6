// SPDX-License-Identifier: MIT
#include "summary.hpp"

#include <algorithm>

#include "outputs.hpp"
#include "stats.hpp"

namespace poursim {

void print_episode(std::FILE *f, int k, const Episode &e) {
  std::fprintf(f,
               "episode %d seed %u: poured %5.1f %% (%5.2f L)  spilled %4.1f %% (%4.2f L)  left %4.1f %%  finish %s"
               "  peak %.2f rad/s %.0f rad/s²  reversals %d  return %.1f\n",
               k, e.seed, 100 * e.m.poured, e.m.poured * e.m.liquid_l, 100 * e.m.spilled, e.m.spilled * e.m.liquid_l,
               100 * e.m.remaining,
               e.m.finish_time < 0 ? "  -   " : (std::to_string(e.m.finish_time).substr(0, 5) + " s").c_str(),
               e.m.peak_omega, e.m.peak_alpha, e.m.reversals, e.m.ret);
  if (e.m.faults != 0)
    std::fprintf(f, "episode %d seed %u: the core faulted (0x%04x) at step %d: controlled stop, then the brake\n", k,
                 e.seed, static_cast<unsigned>(e.m.faults), e.m.fault_step);
}

void print_summary(std::FILE *f, bool json, const std::string &controller, uint32_t seed0, double tau_max,
                   const std::vector<Episode> &eps) {
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
                 "\"faulted\": %d, \"per_episode\": [",
                 json_quote(controller).c_str(), episodes, seed0, tau_max, mean(poured), stdev(poured), mean(spilled),
                 stdev(spilled), mean(poured_l), mean(spilled_l), finish.empty() ? -1.0 : mean(finish), max_finish,
                 unfinished, mean(peak_omega), max_peak, mean(peak_alpha), mean(reversals), mean(ret), stdev(ret),
                 faulted);
    for (size_t k = 0; k < eps.size(); ++k) {
      const Episode &e = eps[k];
      std::fprintf(f,
                   "%s{\"seed\": %u, \"poured_pct\": %.3f, \"spilled_pct\": %.3f, \"liquid_l\": %.4f, "
                   "\"finish_s\": %.4f, \"peak_omega_rad_s\": %.4f, \"peak_alpha_rad_s2\": %.3f, \"reversals\": %d, "
                   "\"return\": %.4f, \"faults\": %d, \"fault_step\": %d}",
                   k ? ", " : "", e.seed, 100 * e.m.poured, 100 * e.m.spilled, e.m.liquid_l, e.m.finish_time,
                   e.m.peak_omega, e.m.peak_alpha, e.m.reversals, e.m.ret, e.m.faults, e.m.fault_step);
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
