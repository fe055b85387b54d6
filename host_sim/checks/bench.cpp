// SPDX-License-Identifier: MIT
// Measures and prints; passes or fails nothing on timing (the tests pin the physics, not the speed).
#include "bench.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "controllers.hpp"
#include "poursim/checks.h"
#include "poursim/poursim.h"
#include "poursim/weights_file.h"
#include "stats.hpp"

namespace poursim {

namespace {

constexpr double kDeg = M_PI / 180.0;

double cpu_s(clockid_t clock) {
  timespec ts;
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// 1. Real time on one core, contact quality and compression, over hand-written pours (the liquid moves
// all episode long).
int bench_speed(const poursim_config_t &cfg, int episodes) {
  char err[POURSIM_ERR_LEN];
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  if (w == nullptr) {
    std::fprintf(stderr, "host_sim: %s\n", err);
    return 1;
  }
  auto hand = make_hand_controller(cfg);
  std::vector<double> rtf, rtf_wall;
  double rest_overlap = 0, end_overlap = 0, rest_density = 0, peak_density = 0;
  for (int k = 0; k < episodes; ++k) {
    uint32_t seed = static_cast<uint32_t>(k + 1);
    poursim_reset(w, seed);
    hand->reset(seed);
    rest_overlap = std::max(rest_overlap, poursim_max_overlap(w));
    rest_density = std::max(rest_density, poursim_max_density_ratio(w));
    poursim_obs_t o;
    poursim_observe(w, &o);
    double c0 = cpu_s(CLOCK_THREAD_CPUTIME_ID);
    auto t0 = std::chrono::steady_clock::now();
    while (!o.done) {
      if (poursim_step(w, hand->command(o), &o) != POURSIM_OK) {
        std::fprintf(stderr, "host_sim: %s\n", poursim_world_error(w));
        poursim_destroy(w);
        return 1;
      }
      peak_density = std::max(peak_density, poursim_max_density_ratio(w));
    }
    rtf.push_back(cfg.episode_s / (cpu_s(CLOCK_THREAD_CPUTIME_ID) - c0));
    rtf_wall.push_back(cfg.episode_s / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    end_overlap = std::max(end_overlap, poursim_max_overlap(w));
  }
  poursim_destroy(w);
  std::printf("real-time factor, one core: %.1fx by CPU time (min %.1fx), %.1fx by wall time, over %d episodes "
              "of %.0f s\n", mean(rtf), *std::min_element(rtf.begin(), rtf.end()), mean(rtf_wall), episodes,
              cfg.episode_s);
  std::printf("contacts: deepest circle-wall overlap %.3f mm at rest, %.3f mm at episode end\n", 1e3 * rest_overlap,
              1e3 * end_overlap);
  if (cfg.fluid)
    std::printf("compression: densest particle %.3f x rest density at rest, %.3f x at worst during a pour\n",
                rest_density, peak_density);
  return 0;
}

// 2. Episodes per second with the C rollout, 1 and 2 threads.
int bench_rollouts(const poursim_config_t &cfg, const std::string &policy_path) {
  char err[POURSIM_ERR_LEN];
  std::vector<double> wbuf(POURSIM_N_FEATURES * POURSIM_MAX_ACTIONS), lbuf(POURSIM_MAX_ACTIONS);
  poursim_policy_t pol{};
  poursim_weights_file_t wf;
  if (!policy_path.empty()) {
    if (poursim_weights_load(policy_path.c_str(), &wf, err, sizeof err) != POURSIM_OK) {
      std::fprintf(stderr, "host_sim: %s\n", err);
      return 1;
    }
    poursim_weights_float_policy(&wf, wbuf.data(), lbuf.data(), &pol);
  } else {
    // Uniform random policy over 11 levels: sampled actions, as in training.
    pol.n_actions = 11;
    pol.decision_period = 10;
    for (int i = 0; i < 11; ++i) lbuf[static_cast<size_t>(i)] = -1.0 + 2.0 * i / 10.0;
    pol.w = wbuf.data();
    pol.levels = lbuf.data();
    // W = 0: every action equally likely whatever the features, so any non-empty normalisation does.
    pol.theta_max = 1.0;
    pol.omega_max = 1.0;
  }
  pol.greedy = 0;
  pol.reward = poursim_default_reward();
  const int batch = 8;
  std::vector<uint32_t> seeds(batch);
  for (int i = 0; i < batch; ++i) seeds[static_cast<size_t>(i)] = static_cast<uint32_t>(100 + i);
  std::vector<poursim_episode_t> eps(batch);
  for (int threads = 1; threads <= 2; ++threads) {
    double c0 = cpu_s(CLOCK_PROCESS_CPUTIME_ID);
    auto t0 = std::chrono::steady_clock::now();
    int rc = poursim_rollout_batch(&cfg, &pol, seeds.data(), batch, threads, nullptr, eps.data(), err, sizeof err);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double cpu = cpu_s(CLOCK_PROCESS_CPUTIME_ID) - c0;
    if (rc != POURSIM_OK) {
      std::fprintf(stderr, "host_sim: %s\n", err);
      return 1;
    }
    std::printf("rollouts (C, %s policy): %d episodes on %d thread%s in %.2f s wall = %.2f episodes/s "
                "(%.2f s CPU, %.2f episodes per CPU-second)\n",
                policy_path.empty() ? "random" : "given", batch, threads, threads > 1 ? "s" : "", s, batch / s, cpu,
                batch / cpu);
  }
  return 0;
}

// The first angle at which at most half the liquid is left [deg].
double half_out(const double *kept, const poursim_retention_t &r) {
  for (int i = 0; i < r.n; ++i)
    if (kept[i] <= 0.5) return r.theta[i] / kDeg;
  return -1.0;
}

// 3. The liquid against hydrostatics and linear sloshing theory (docs/simulator.md), and the rigid pile of
// the first wave against the same reference.
int bench_physics(const poursim_config_t &cfg) {
  char err[POURSIM_ERR_LEN];
  const double depth = cfg.bucket_height - cfg.bucket_wall;
  struct Case {
    double fill, rate;
    int fluid, seeds;
  };
  const Case cases[] = {{0.60, 0.02, 1, 3}, {0.70, 0.02, 1, 3}, {0.85, 0.02, 1, 3}, {0.70, 0.1, 1, 3}, {0.70, 0.02, 0, 1}};
  std::printf("retention, servo tilt to 125 deg, against an ideal liquid (level surface through the lower lip):\n");
  for (const Case &k : cases) {
    poursim_config_t c = cfg;
    c.fill_depth = k.fill * depth;
    c.fluid = k.fluid;
    poursim_retention_t r;
    if (poursim_measure_retention(&c, 1, k.seeds, k.rate, 125 * kDeg, &r, err, sizeof err) != POURSIM_OK) {
      std::fprintf(stderr, "host_sim: %s\n", err);
      return 1;
    }
    std::printf("  %s, fill %.0f %% (%.3f m), %.2f rad/s, seeds 1-%d: onset %.0f deg (ideal %.0f, %+.0f), half out at "
                "%.0f deg (ideal %.0f), RMS gap %.1f %% of the liquid over 0-125 deg\n",
                k.fluid ? "fluid" : "rigid pile (fluid = 0)", 100 * k.fill, c.fill_depth, k.rate, k.seeds,
                r.onset / kDeg, r.ideal_onset / kDeg, (r.onset - r.ideal_onset) / kDeg, half_out(r.kept, r),
                half_out(r.ideal, r), 100 * r.rms_gap);
  }
  poursim_slosh_t s;
  if (poursim_measure_slosh(&cfg, 1, 16, 12 * kDeg, 0.3, 4.0, nullptr, 0, &s, err, sizeof err) != POURSIM_OK) {
    std::fprintf(stderr, "host_sim: %s\n", err);
    return 1;
  }
  std::printf("sloshing, tilt to 12 deg in 0.3 s and hold, mean of seeds 1-16: %.3f Hz against %.3f Hz "
              "(rectangular tank, first mode; %+.1f %%), damping ratio %.3f, amplitude %.2f mm over a noise of "
              "%.2f mm\n",
              s.freq, s.freq_theory, 100 * (s.freq / s.freq_theory - 1), s.damping, 1e3 * s.amplitude, 1e3 * s.noise);
  return 0;
}

// 4. The rig: the drive against Newton and its datasheet line, the sensors against mass, momentum and
// their config (the same C functions as tests/sim/test_rig.c).
int bench_rig(const poursim_config_t &cfg) {
  char err[POURSIM_ERR_LEN];
  poursim_drive_check_t d;
  if (poursim_measure_drive(&cfg, &d, err, sizeof err) != POURSIM_OK) {
    std::fprintf(stderr, "host_sim: %s\n", err);
    return 1;
  }
  std::printf("drive, empty bucket: latency %d tick(s) (config %d); inertia %.5f kg m^2 by spin-up against %.5f "
              "(U by hand %.5f + rotor J N^2 %.5f, %+.2f %%); Coulomb breakaway at %.3f N m (config %.3f)\n",
              d.latency_ticks, cfg.command_latency_ticks, d.inertia_measured, d.inertia_expected, d.inertia_bucket,
              d.inertia_expected - d.inertia_bucket, 100 * (d.inertia_measured / d.inertia_expected - 1),
              d.breakaway_torque, cfg.friction_coulomb);
  for (int r = 0; r < 2; ++r)
    std::printf("  full command, Coulomb %.1f N m: terminal speed %.3f rad/s, datasheet line %.3f rad/s (%+.2f %%)\n",
                d.terminal_load[r], d.terminal_speed[r], d.terminal_expected[r],
                100 * (d.terminal_speed[r] / d.terminal_expected[r] - 1));
  for (int r = 0; r < POURSIM_FRICTION_SPEEDS; ++r)
    std::printf("  friction at %.3f rad/s: %.4f N m by Newton, F_c + b w %.4f N m (%+.4f N m)\n", d.friction_speed[r],
                d.friction_measured[r], d.friction_expected[r], d.friction_measured[r] - d.friction_expected[r]);
  poursim_sensor_check_t s;
  if (poursim_measure_sensors(&cfg, 1, &s, err, sizeof err) != POURSIM_OK) {
    std::fprintf(stderr, "host_sim: %s\n", err);
    return 1;
  }
  std::printf("encoder (%d bits): largest error %.4f counts over -5..125 deg; at the lower stop %u (2^%d - %u)\n",
              cfg.encoder_bits, s.encoder_max_error, s.encoder_at_stop, cfg.encoder_bits,
              (1u << cfg.encoder_bits) - s.encoder_at_stop);
  std::printf("scales, servo pour (upright 1 s, 0.5 rad/s to 125 deg, 3 s): at rest the rotating cell reads %.1f g "
              "of %.1f g of liquid (%+.2f %%), the target %.1f g of the %.1f g inside it (%+.2f %%)\n",
              s.rest_rotating_g, s.liquid_g, 100 * (s.rest_rotating_g / s.liquid_g - 1), s.rest_target_g,
              s.target_liquid_g, 100 * (s.rest_target_g / s.target_liquid_g - 1));
  std::printf("  %.2f conversions/s (config %.0f Hz), filter span %.4f s (config %.4f s; %.1f %% of the conversions "
              "within a resolution of the every-step load's mean over it), noise %.3f g RMS against %.3f g (%.2f g "
              "quantised to %.0f g)\n",
              s.update_rate_hz, cfg.scale_rate_hz, s.delay_s, cfg.scale_delay_s, 100 * s.delay_match, s.noise_rms_g,
              s.noise_expected_g, cfg.scale_noise_g, cfg.scale_resolution_g);
  std::printf("  impact: the target reads %.1f g s beyond the liquid inside it over the pour, the stream's momentum "
              "is %.1f g s (%+.1f %%); at its peak the impact is %.0f g on a reading of %.0f g; trajectory hash "
              "%s by the scales' noise, lag and rate\n",
              s.impact_impulse_gs, s.impact_expected_gs, 100 * (s.impact_impulse_gs / s.impact_expected_gs - 1),
              s.impact_peak_g, s.impact_peak_reading_g, s.hash_unchanged ? "unchanged" : "CHANGED");
  return 0;
}

} // namespace

int run_bench(const poursim_config_t &cfg, const std::string &policy_path, int episodes) {
  double load[3] = {0, 0, 0};
  if (std::FILE *f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3) load[0] = -1;
    std::fclose(f);
  }
  std::printf("host_sim bench: %d particles (%s), dt %.4f s, %d substeps, contact %.0f Hz; load average %.2f %.2f "
              "%.2f\n",
              cfg.n_particles, cfg.fluid ? "fluid" : "rigid pile", cfg.dt, cfg.substeps, cfg.contact_hertz, load[0],
              load[1], load[2]);
  std::fflush(stdout);
  int rc = bench_speed(cfg, std::max(3, std::min(episodes, 10)));
  std::fflush(stdout);
  if (rc == 0) rc = bench_rollouts(cfg, policy_path);
  std::fflush(stdout);
  if (rc == 0) rc = bench_physics(cfg);
  std::fflush(stdout);
  if (rc == 0) rc = bench_rig(cfg);
  return rc;
}

} // namespace poursim
