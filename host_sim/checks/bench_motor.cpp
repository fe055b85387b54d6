// SPDX-License-Identifier: MIT
// bench_motor: the full drive's figures (docs/motor.md): the current step against the design bandwidth,
// the shaft torque from standstill to base speed, the bus through the shipped policy's pour and return to
// upright (flux braking on and off), and the cost of the full drive against the ideal one. Measures and
// prints; passes or fails nothing (tests/sim/test_motor_checks.cpp holds the bars).
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "motor_checks.hpp"
#include "outputs.hpp"

namespace {

int usage(FILE *f = stderr) {
  std::fprintf(f,
               "usage: bench_motor [--weights FILE] [--seed S] [--step-csv FILE] [--bus-csv FILE]\n"
               "  prints the current step, the torque against speed, the bus through the pour with flux\n"
               "  braking on and off, and the full drive's cost; the CSVs are the traces for the plots\n");
  return 2;
}

bool write_csv(const std::string &path, const char *header, const std::vector<double> &t,
               const std::vector<double> &y, std::string *why) {
  poursim::AtomicFile f;
  if (!f.open(path, why)) return false;
  std::fprintf(f.stream(), "%s\n", header);
  for (size_t k = 0; k < t.size(); ++k) std::fprintf(f.stream(), "%.9g,%.9g\n", t[k], y[k]);
  return f.commit(why);
}

double seconds_per_episode(const poursim_config_t &c, const std::string &weights, uint32_t seed) {
  poursim::BusTrace b;
  std::string why;
  // processor time, not the wall clock: the machine is shared, and this measures the code
  const std::clock_t t0 = std::clock();
  if (!poursim::measure_pour_bus(c, weights, seed, 0.0, &b, &why)) return -1.0;
  return static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
}

} // namespace

int main(int argc, char **argv) {
  std::string weights = "policy/weights.h", step_csv, bus_csv;
  uint32_t seed = 1;
  if (argc == 2 && std::string(argv[1]) == "--help") {
    usage(stdout);
    return 0;
  }
  if (argc == 2 && std::string(argv[1]) == "--version") {
    std::printf("bench_motor %s\n", POUR_VERSION);
    return 0;
  }
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage();
    if (a == "--weights") weights = argv[++i];
    else if (a == "--seed") seed = static_cast<uint32_t>(std::strtoul(argv[++i], nullptr, 10));
    else if (a == "--step-csv") step_csv = argv[++i];
    else if (a == "--bus-csv") bus_csv = argv[++i];
    else return usage();
  }
  poursim_config_t c = poursim_default_config();
  c.drive = 1;
  std::string why;

  const poursim::CurrentStep s = poursim::measure_current_step(c, 10.0);
  std::printf("current step %.1f A (locked rotor): rise 10-90 %% %.3f ms (design bandwidth with the loop's delay: "
              "%.3f ms, %+.1f %%; delay-free first order: %.3f ms, %+.1f %%), overshoot %.2f %%, steady-state "
              "error %.3f %%\n",
              s.ref, s.rise_s * 1e3, s.predicted_rise_s * 1e3, 100.0 * (s.rise_s / s.predicted_rise_s - 1.0),
              s.first_order_rise_s * 1e3, 100.0 * (s.rise_s / s.first_order_rise_s - 1.0), 100.0 * s.overshoot,
              100.0 * s.ss_error);
  if (!step_csv.empty() && !write_csv(step_csv, "t_s,iq_a", s.t, s.iq, &why)) {
    std::fprintf(stderr, "bench_motor: %s\n", why.c_str());
    return 1;
  }

  const double tau = 20.0;
  std::printf("shaft torque at %.0f N·m, base speed %.2f rad/s at the output:", tau, poursim::base_speed(c, tau));
  double worst = 0;
  for (const poursim::TorquePoint &p : poursim::measure_torque_speed(c, tau, 6)) {
    const double err = (p.delivered - p.command) / p.command;
    worst = std::max(worst, std::fabs(err));
    std::printf(" %.2f rad/s %+.2f %%;", p.omega, 100.0 * err);
  }
  std::printf(" worst %.2f %%\n", 100.0 * worst);

  for (int regen = 1; regen >= 0; --regen) {
    poursim_config_t cr = c;
    cr.drive_regen = regen;
    poursim::BusTrace b;
    if (!poursim::measure_pour_bus(cr, weights, seed, 3.0, &b, &why)) {
      std::fprintf(stderr, "bench_motor: %s\n", why.c_str());
      return 1;
    }
    std::printf("pour + 3 s return, seed %u, flux braking %s: peak bus %.2f V (min %.2f V), peak phase current "
                "%.1f A, faults 0x%04x, poured %.1f %% spilled %.1f %%\n",
                seed, regen ? "on " : "off", b.peak_vbus, b.min_vbus, b.peak_current, b.faults, 100.0 * b.poured,
                100.0 * b.spilled);
    if (regen && !bus_csv.empty() && !write_csv(bus_csv, "t_s,vbus_v", b.t, b.vbus, &why)) {
      std::fprintf(stderr, "bench_motor: %s\n", why.c_str());
      return 1;
    }
  }

  poursim_config_t ideal = c;
  ideal.drive = 0;
  const double t_ideal = seconds_per_episode(ideal, weights, seed), t_foc = seconds_per_episode(c, weights, seed);
  std::printf("processor time of a %.0f s episode: ideal drive %.3f s (%.1fx real time), full drive %.3f s (%.1fx real time)\n",
              c.episode_s, t_ideal, c.episode_s / t_ideal, t_foc, c.episode_s / t_foc);
  return 0;
}
