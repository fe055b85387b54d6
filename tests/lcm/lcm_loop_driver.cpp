// SPDX-License-Identifier: MIT
// Test and benchmark driver for the LCM loop: runs episodes of libpoursim with the firmware core either
// in-process or through pour_controller over LCM (host_sim's lcm_link), and prints the trajectory hash,
// so that the two can be compared bit for bit.
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "lcm_link.hpp"
#include "poursim/poursim.h"

extern "C" {
#include "pour/control.h"
#include "pour/weights_compiled.h"
}

namespace {

void usage(FILE *f) {
  std::fprintf(f,
               "usage: lcm_loop_driver --mode inproc|lcm [--url URL] [--realtime] [--steps N] [--episodes E]\n"
               "                       [--seed S] [--answer-timeout-ms T] [--particles-ms P] [--trace FILE] [--no-sim]\n"
               "  --no-sim   synthetic sensor samples instead of the Box2D world: the loop's own rate (benchmark)\n");
}

bool parse_long(const char *opt, const char *s, long lo, long hi, long *out) {
  char *end = nullptr;
  errno = 0;
  const long v = s != nullptr ? std::strtol(s, &end, 10) : 0;
  if (s == nullptr || end == s || *end != '\0' || errno != 0 || v < lo || v > hi) {
    std::fprintf(stderr, "lcm_loop_driver: %s needs an integer in [%ld, %ld], got '%s'\n", opt, lo, hi,
                 s != nullptr ? s : "(nothing)");
    return false;
  }
  *out = v;
  return true;
}

} // namespace

int main(int argc, char **argv) {
  std::string mode;
  poursim::LcmLinkDef def;
  def.particles_period_ms = 0;
  long steps = 2000, episodes = 1, seed = 1, v = 0;
  const char *trace_path = nullptr;
  bool no_sim = false;
  for (int i = 1; i < argc; i++) {
    const std::string a = argv[i];
    const char *val = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--mode" && val != nullptr) {
      mode = val;
      i++;
    } else if (a == "--url" && val != nullptr) {
      def.url = val;
      i++;
    } else if (a == "--realtime") {
      def.lockstep = false;
    } else if (a == "--steps") {
      if (!parse_long("--steps", val, 1, 100000000, &steps)) return 2;
      i++;
    } else if (a == "--episodes") {
      if (!parse_long("--episodes", val, 1, 1000, &episodes)) return 2;
      i++;
    } else if (a == "--seed") {
      if (!parse_long("--seed", val, 0, 0xffffffffL, &seed)) return 2;
      i++;
    } else if (a == "--answer-timeout-ms") {
      if (!parse_long("--answer-timeout-ms", val, 1, 3600000, &v)) return 2;
      def.answer_timeout_ms = static_cast<int>(v);
      i++;
    } else if (a == "--particles-ms") {
      if (!parse_long("--particles-ms", val, 0, 100000, &v)) return 2;
      def.particles_period_ms = static_cast<int>(v);
      i++;
    } else if (a == "--trace" && val != nullptr) {
      trace_path = val;
      i++;
    } else if (a == "--no-sim") {
      no_sim = true;
    } else if (a == "--help") {
      usage(stdout);
      return 0;
    } else if (a == "--version") {
      std::printf("lcm_loop_driver %s\n", POUR_VERSION);
      return 0;
    } else {
      std::fprintf(stderr, "lcm_loop_driver: unknown or incomplete option '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    }
  }
  if (mode != "inproc" && mode != "lcm") {
    std::fprintf(stderr, "lcm_loop_driver: --mode must be inproc or lcm\n");
    return 2;
  }

  char err[POURSIM_ERR_LEN] = "";
  poursim_config_t cfg = poursim_default_config();
  cfg.episode_s = static_cast<double>(steps) * cfg.dt;
  poursim_world_t *world = poursim_create(&cfg, err, sizeof err);
  if (world == nullptr) {
    std::fprintf(stderr, "lcm_loop_driver: %s\n", err);
    return 1;
  }
  std::unique_ptr<poursim::LcmLink> link;
  if (mode == "lcm") {
    std::string e;
    link = poursim::LcmLink::open(def, &e);
    if (!link) {
      std::fprintf(stderr, "lcm_loop_driver: %s\n", e.c_str());
      return 1;
    }
  }
  FILE *trace = trace_path != nullptr ? std::fopen(trace_path, "w") : nullptr;
  if (trace_path != nullptr && trace == nullptr) {
    std::fprintf(stderr, "lcm_loop_driver: cannot write %s\n", trace_path);
    return 1;
  }
  const pour_control_config_t ccfg = pour_control_default_config();
  pour_control_t ctl;
  poursim_obs_t obs{};
  const auto t_start = std::chrono::steady_clock::now();
  int rc = 0;
  for (long ep = 0; ep < episodes && rc == 0; ep++) {
    poursim_reset(world, static_cast<uint32_t>(seed + ep));
    if (pour_control_init(&ctl, &ccfg, &pour_weights_compiled) != POUR_OK) {
      std::fprintf(stderr, "lcm_loop_driver: the core refused the built-in weights\n");
      return 1;
    }
    if (link) {
      link->request_new_run(); // the controller has no episodes: a new run is an explicit command
    }
    poursim_observe(world, &obs);
    for (long k = 0; k < steps; k++) {
      int16_t q15 = 0;
      if (link) {
        std::string e;
        if (!link->exchange(static_cast<int>(ep), obs, &q15, &e)) {
          std::fprintf(stderr, "lcm_loop_driver: %s\n", e.c_str());
          rc = 3;
          break;
        }
        link->maybe_publish_particles(world, obs);
      } else {
        // The sample as host_sim's in-process controller takes it (seq = step); over LCM the same integers.
        pour_control_input_t in;
        std::memset(&in, 0, sizeof in);
        in.sensors_fresh = true;
        in.sensors = pour_sensors_t{obs.step, obs.encoder, obs.scale_rotating_g, obs.scale_target_g};
        pour_control_output_t out;
        pour_control_step(&ctl, &in, &out);
        q15 = out.torque;
      }
      if (trace != nullptr) {
        std::fprintf(trace, "%ld %u %u %d %d %.17g %.17g %d\n", ep, obs.step, obs.encoder, obs.scale_rotating_g,
                     obs.scale_target_g, obs.theta, obs.omega, q15);
      }
      if (no_sim) {
        // A plausible sample that changes every tick, at no physics cost: the encoder sweeps 0 .. 1.9 rad
        // at 0.1 rad/s, and liquid moves from one scale to the other at 0.1 kg/s (5 kg every 50 s).
        obs.step = static_cast<uint32_t>(k + 1);
        obs.t = static_cast<double>(k + 1) * 1e-3;
        obs.encoder = static_cast<uint32_t>((k % 20000) * 2);
        obs.scale_rotating_g = static_cast<int32_t>(10000 - (k / 10) % 5000);
        obs.scale_target_g = static_cast<int32_t>((k / 10) % 5000);
      } else if (poursim_step(world, static_cast<double>(q15) / 32768.0, &obs) != POURSIM_OK) {
        break;
      }
    }
  }
  const auto wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  std::printf("steps %ld wall_s %.3f steps_per_s %.0f\n", steps * episodes, wall_s,
              static_cast<double>(steps * episodes) / wall_s);
  if (link) {
    link->drain(50);
    std::printf("%s\n", link->summary().c_str());
  }
  std::printf("trajectory_hash %016" PRIx64 " theta %.9g v_target %.9g v_spill %.9g\n",
              poursim_trajectory_hash(world), obs.theta, obs.v_target, obs.v_spill);
  if (trace != nullptr) std::fclose(trace);
  poursim_destroy(world);
  return rc;
}
