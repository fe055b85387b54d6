// SPDX-License-Identifier: MIT
// host_sim: runs pours in the Box2D world with the firmware core in-process (or a baseline), prints
// results, writes trajectories and renders them. `host_sim --help` explains the flags.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <getopt.h>

#include "bench.hpp"
#include "controllers.hpp"
#include "episode_run.hpp"
#include "experiment_log.hpp"
#include "lcm_link.hpp"
#include "outputs.hpp"
#include "poursim/poursim.h"
#include "poursim/weights_file.h"
#include "renderer.hpp"
#include "summary.hpp"

namespace {

const char *kUsage =
    "usage: host_sim (--policy WEIGHTS_H | --baseline NAME | --bench | --experiment KIND --candump LOG) [options]\n"
    "\n"
    "Pours a bucket of simulated liquid (150 particles of a fluid, Box2D) into a second bucket and reports how\n"
    "much landed in the target, how much was spilled, how long the pour took and the return.\n"
    "\n"
    "What drives the bucket (one of):\n"
    "  --policy FILE       a weights.h (as exported by the trainer): parsed and checked at run time,\n"
    "                      run by the firmware core in-process (the same C code that is flashed)\n"
    "  --baseline NAME     rate  : tilt at a constant rate to the stop (--rate, default 1.5 rad/s)\n"
    "                      full  : full torque all the way\n"
    "                      hand  : hand-written good pour (fast to the lip, then slowly)\n"
    "  --bench             measure speed, contact quality, episodes/s, and the liquid against physics:\n"
    "                      retention curve vs an ideal liquid, sloshing vs linear theory (~2 min)\n"
    "                      (with --policy: the rollouts run that policy, else a uniform random one)\n"
    "  --lcm [URL]         pour_controller, a separate process, over LCM (POUR_SENSORS out, POUR_TORQUE in,\n"
    "                      POUR_TRUTH, POUR_PARTICLES for viewers); lockstep unless --realtime. With\n"
    "                      --policy, the file sets tau_max and the controller must run that policy.\n"
    "                      Exit status 3 if the controller does not answer, 4 if it runs other weights.\n"
    "  --experiment KIND   the controller's own identification experiment (docs/bench.md), started over\n"
    "                      its CAN node as pour-bench identify starts it: identify (bucket emptied: torque\n"
    "                      steps and a chirp about 20 deg) or tilt (with the liquid: to 90 deg at 0.1 rad/s\n"
    "                      and back); --candump LOG gets the bus traffic as candump -L writes it, for\n"
    "                      pour-sysid. Exit status 1 if it did not run to its end (out of range, a fault)\n"
    "\n"
    "Options:\n"
    "  --episodes N        episodes to run (default 1), seeds S, S+1, ...\n"
    "  --seed S            first seed (default: the config's seed, 1)\n"
    "  --config FILE       simulator config, 'key = value' lines (configs/sim/default.cfg)\n"
    "  --set KEY=VALUE     override one config value (repeatable)\n"
    "  --sampled           sample the policy's actions (seeded) instead of greedy argmax\n"
    "  --core-reset        one firmware core for every episode, restarted between them by ClearErrors, Stop\n"
    "                      and Reset in the next episode's first tick, as --lcm and the CAN bridge restart\n"
    "                      pour_controller (default: a fresh core each episode, as at power-on)\n"
    "  --rate R            rate of the 'rate' baseline [rad/s]\n"
    "  --json              print the summary as one JSON object (per-episode lines go to stderr)\n"
    "  --csv FILE          write every step of every episode as CSV\n"
    "  --render FILE       animate the first episode into FILE (.gif, or .mp4 with ffmpeg), and write\n"
    "                      a .png snapshot beside it (same name), with the program $POUR_RENDER if set,\n"
    "                      else pour-render (the tools' entry point, in the venv's bin) found on PATH\n"
    "  --quiet             only the summary\n"
    "  --realtime          with --lcm: pace at 1 kHz wall clock, use the latest torque, count misses\n"
    "  --lcm-timeout-ms T  with --lcm in lockstep: give up after T ms without an answer (default 2000)\n"
    "  --candump LOG       with --experiment: the log to write\n"
    "  --node N            with --experiment: the controller's CAN node id (default 0)\n"
    "  --list-config       every config key with its unit, range and default\n"
    "  --help, --version   this text; the version\n"
    "Options take their value as --key VALUE or --key=VALUE (--lcm: --lcm=URL, --lcm URL or --lcm alone).\n"
    "\n"
    "Results, per episode and as a summary over episodes:\n"
    "  poured   % of the liquid in the target bucket at the end of the episode (10 s)\n"
    "  spilled  % on the ground (outside both buckets, below the target's rim)\n"
    "  left     % still in the rotating bucket\n"
    "  finish   time until 99 % of what left the bucket had landed (in the target or spilled)\n"
    "  return   sum over 1 ms steps of gamma^t (k_target*V_target - k_spill*V_spill); --set k_target=, k_spill=,\n"
    "           gamma= (defaults 1, 5, 0.9995) set the reward, which is not part of the world's config\n"
    "Outputs (--csv, --render and its .png and .json) are checked before the run: none may name an input\n"
    "or another output. Each is written beside its target and renamed over it when complete, so a failed\n"
    "or interrupted run leaves an existing file as it was.\n"
    "Exit status (the same meanings in every pour program): 0 done; 1 a failure while running (writing an\n"
    "output, the renderer, the LCM link, the simulated world); 2 bad input, refused before any work: the\n"
    "command line, or a file it names (policy, config, an output path that cannot be written or names an\n"
    "input), or a program --render needs (pour-render, ffmpeg) that cannot be found; 3 (--lcm) the\n"
    "controller does not answer; 4 (--lcm) it runs other weights.\n"
    "\n"
    "Examples:\n"
    "  host_sim --policy policy/weights.h --render pour.gif\n"
    "  host_sim --baseline rate --episodes 5 --json\n"
    "  host_sim --policy policy/weights.h --episodes 20 --set k_spill=10 --csv run.csv\n"
    "  host_sim --experiment identify --candump identify.log\n";

constexpr int kFrameEverySteps = 80; // 12.5 frames/s at 1 ms: smooth enough, and a GIF of 10 s renders in seconds

struct Options {
  std::string policy, baseline, config_path, csv, render, experiment, candump;
  int node_id = 0;
  bool bench = false, sampled = false, core_reset = false, json = false, quiet = false;
  int episodes = 1;
  long long seed = -1;
  double rate = 1.5;
  std::vector<std::string> sets;
  bool lcm = false, realtime = false;
  std::string lcm_url;
  int lcm_timeout_ms = 2000;
};

int usage_error(const char *fmt, const char *arg) {
  std::fprintf(stderr, "host_sim: ");
  std::fprintf(stderr, fmt, arg);
  std::fprintf(stderr, "\n(run host_sim --help for usage)\n");
  return 2;
}

bool parse_long(const char *s, long long lo, long long hi, long long &out) {
  char *end = nullptr;
  errno = 0;
  long long v = std::strtoll(s, &end, 10);
  if (end == s || *end != '\0' || errno != 0 || v < lo || v > hi) return false;
  out = v;
  return true;
}

// Levenshtein distance, for the suggestion on an unknown config key.
size_t edit_distance(const std::string &a, const std::string &b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// poursim_config_describe's text: one key a line, the key first.
std::string config_description() {
  std::vector<char> buf(16384);
  if (poursim_config_describe(buf.data(), buf.size()) != POURSIM_OK) return "";
  return buf.data();
}

// The config key nearest to key (at most a third of its letters off), or "" when none is near.
std::string nearest_config_key(const std::string &key) {
  const std::string text = config_description();
  std::string best;
  size_t best_d = key.size() / 3 + 1;
  for (size_t at = 0; at < text.size();) {
    size_t eol = text.find('\n', at);
    if (eol == std::string::npos) eol = text.size();
    const size_t b = text.find_first_not_of(' ', at);
    const size_t e = text.find(' ', b);
    if (b < eol && e != std::string::npos) {
      const std::string name = text.substr(b, std::min(e, eol) - b);
      const size_t d = edit_distance(key, name);
      if (d < best_d) best_d = d, best = name;
    }
    at = eol + 1;
  }
  return best;
}

// For an error on --set KEY=...: a hint when KEY is no config key (the nearest one, or where the list is).
std::string key_hint(const std::string &key) {
  const std::string near = nearest_config_key(key);
  if (near == key) return "";
  if (near.empty()) return " (host_sim --list-config lists the keys)";
  return " (did you mean '" + near + "'? host_sim --list-config lists the keys)";
}

enum {
  kOptPolicy = 256, kOptBaseline, kOptConfig, kOptCsv, kOptRender, kOptEpisodes, kOptSeed, kOptSet, kOptRate,
  kOptLcm, kOptRealtime, kOptLcmTimeout, kOptBench, kOptSampled, kOptCoreReset, kOptJson, kOptQuiet, kOptListConfig, kOptVersion,
  kOptExperiment, kOptCandump, kOptNodeId
};

const option kOptions[] = {
    {"help", no_argument, nullptr, 'h'},
    {"version", no_argument, nullptr, kOptVersion},
    {"list-config", no_argument, nullptr, kOptListConfig},
    {"policy", required_argument, nullptr, kOptPolicy},
    {"baseline", required_argument, nullptr, kOptBaseline},
    {"config", required_argument, nullptr, kOptConfig},
    {"csv", required_argument, nullptr, kOptCsv},
    {"render", required_argument, nullptr, kOptRender},
    {"episodes", required_argument, nullptr, kOptEpisodes},
    {"seed", required_argument, nullptr, kOptSeed},
    {"set", required_argument, nullptr, kOptSet},
    {"rate", required_argument, nullptr, kOptRate},
    {"lcm", optional_argument, nullptr, kOptLcm},
    {"realtime", no_argument, nullptr, kOptRealtime},
    {"lcm-timeout-ms", required_argument, nullptr, kOptLcmTimeout},
    {"bench", no_argument, nullptr, kOptBench},
    {"sampled", no_argument, nullptr, kOptSampled},
    {"core-reset", no_argument, nullptr, kOptCoreReset},
    {"json", no_argument, nullptr, kOptJson},
    {"quiet", no_argument, nullptr, kOptQuiet},
    {"experiment", required_argument, nullptr, kOptExperiment},
    {"candump", required_argument, nullptr, kOptCandump},
    {"node", required_argument, nullptr, kOptNodeId},
    {nullptr, 0, nullptr, 0},
};

// Returns -1 to continue, else the exit code.
int parse_args(int argc, char **argv, Options &o) {
  opterr = 0;  // our own messages
  int opt;
  while ((opt = getopt_long(argc, argv, "+:h", kOptions, nullptr)) != -1) {
    const char *a = argv[optind - 1];
    const char *v = optarg;
    long long n = 0;
    switch (opt) {
    case 'h':
      std::fputs(kUsage, stdout);
      return 0;
    case kOptVersion:
      std::printf("host_sim %s (policies are parsed at run time: --policy FILE)\n", POUR_VERSION);
      return 0;
    case kOptListConfig:
      std::printf("Simulator config keys (--set KEY=VALUE, or 'key = value' lines in --config FILE):\n%s",
                  config_description().c_str());
      return 0;
    case kOptPolicy: o.policy = v; break;
    case kOptBaseline: o.baseline = v; break;
    case kOptConfig: o.config_path = v; break;
    case kOptCsv:
    case kOptRender:
      if (*v == '\0') return usage_error("%s: the file name is empty", opt == kOptCsv ? "--csv" : "--render");
      (opt == kOptCsv ? o.csv : o.render) = v;
      break;
    case kOptSet: o.sets.push_back(v); break;
    case kOptEpisodes:
      if (!parse_long(v, 1, 100000, n)) return usage_error("--episodes wants an integer 1..100000, got '%s'", v);
      o.episodes = static_cast<int>(n);
      break;
    case kOptSeed:
      if (!parse_long(v, 0, 4294967295LL, n)) return usage_error("--seed wants an integer 0..4294967295, got '%s'", v);
      o.seed = n;
      break;
    case kOptRate: {
      char *end = nullptr;
      o.rate = std::strtod(v, &end);
      if (end == v || *end != '\0' || !(o.rate > 0.0 && o.rate < 100.0))
        return usage_error("--rate wants a rate in (0, 100) rad/s, got '%s'", v);
      break;
    }
    case kOptLcm:
      o.lcm = true;
      // --lcm=URL, --lcm URL (a next word that is not an option), or --lcm alone (the default URL).
      if (v != nullptr) o.lcm_url = v;
      else if (optind < argc && argv[optind][0] != '-') o.lcm_url = argv[optind++];
      break;
    case kOptRealtime: o.realtime = true; break;
    case kOptLcmTimeout:
      if (!parse_long(v, 1, 3600000, n)) return usage_error("--lcm-timeout-ms wants an integer 1..3600000, got '%s'", v);
      o.lcm_timeout_ms = static_cast<int>(n);
      break;
    case kOptBench: o.bench = true; break;
    case kOptSampled: o.sampled = true; break;
    case kOptCoreReset: o.core_reset = true; break;
    case kOptJson: o.json = true; break;
    case kOptQuiet: o.quiet = true; break;
    case kOptExperiment:
      if (std::strcmp(v, "identify") != 0 && std::strcmp(v, "tilt") != 0)
        return usage_error("--experiment wants identify or tilt, got '%s'", v);
      o.experiment = v;
      break;
    case kOptCandump:
      if (*v == '\0') return usage_error("%s", "--candump: the file name is empty");
      o.candump = v;
      break;
    case kOptNodeId:
      if (!parse_long(v, 0, 63, n)) return usage_error("--node wants an integer 0..63, got '%s'", v);
      o.node_id = static_cast<int>(n);
      break;
    case ':': return usage_error("%s needs a value", a);
    default: return usage_error("unknown option '%s'", a);
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  // --bench may take a --policy (its rollouts then run that policy).
  int modes = (o.policy.empty() || o.bench ? 0 : 1) + (o.baseline.empty() ? 0 : 1) + (o.bench ? 1 : 0) +
              (o.experiment.empty() ? 0 : 1);
  if (o.experiment.empty() != o.candump.empty()) return usage_error("%s", "--experiment and --candump go together");
  if (!o.experiment.empty() && (o.lcm || !o.policy.empty()))
    return usage_error("%s", "--experiment runs the controller in-process, with no policy: no --lcm, no --policy");
  if (o.lcm && (o.bench || !o.baseline.empty())) return usage_error("%s", "--lcm goes with --policy FILE or alone");
  if (o.realtime && !o.lcm) return usage_error("%s", "--realtime needs --lcm");
  if (o.core_reset && (o.lcm || o.policy.empty()))
    return usage_error("%s", "--core-reset goes with --policy FILE and no --lcm (the linked controller restarts so)");
  if (o.lcm && modes == 0) modes = 1;
  if (modes != 1)
    return usage_error("%s", "choose exactly one of --policy FILE, --baseline NAME, --bench, --experiment KIND");
  if (!o.baseline.empty() && o.baseline != "rate" && o.baseline != "full" && o.baseline != "hand")
    return usage_error("unknown baseline '%s' (rate, full or hand)", o.baseline.c_str());
  return -1;
}

// --experiment: the log written, how the experiment ended on stdout; exit 1 unless it ran to its end.
int run_experiment_cli(const Options &o, const poursim_config_t &cfg) {
  std::string why;
  if (!poursim::check_outputs({{"--candump", o.candump}}, {{"--config", o.config_path}}, &why)) {
    std::fprintf(stderr, "host_sim: %s\n", why.c_str());
    return 2;
  }
  poursim::ExperimentRun run;
  run.kind = o.experiment == "tilt" ? POUR_EXPERIMENT_TILT : POUR_EXPERIMENT_IDENTIFY;
  run.seed = o.seed >= 0 ? static_cast<uint32_t>(o.seed) : cfg.seed;
  run.node_id = static_cast<uint8_t>(o.node_id);
  run.path = o.candump;
  poursim::ExperimentResult r;
  if (!poursim::run_experiment(cfg, run, &r, &why)) {
    std::fprintf(stderr, "host_sim: --experiment %s: %s\n", o.experiment.c_str(), why.c_str());
    return 1;
  }
  const bool done = r.phase == POUR_EXPERIMENT_PHASE_DONE && r.faults == 0u;
  std::printf("experiment %s: %u ticks logged to %s; %s (mode %s, faults %s)\n", o.experiment.c_str(), r.ticks,
              o.candump.c_str(),
              done ? "ran to its end, bucket held"
                   : (r.phase == POUR_EXPERIMENT_PHASE_OUT_OF_RANGE ? "ENDED EARLY: the angle left its range"
                                                                     : "ENDED EARLY: a fault or no end"),
              pour_mode_name(r.mode), poursim::core_fault_names(r.faults).c_str());
  return done ? 0 : 1;
}

// What the steps of main() hand on: the configuration the run uses and the policy it runs (if any).
struct Setup {
  poursim_config_t cfg = poursim_default_config();
  poursim_reward_t reward = poursim_default_reward();
  poursim_weights_file_t weights{};
};

// The policy first (the simulator runs at the tau_max the policy was trained with), then --config, each
// --set and the validation. -1 when all is well, else the exit status.
int load_setup(const Options &o, Setup &s) {
  char err[POURSIM_ERR_LEN];
  if (!o.policy.empty()) {
    if (poursim_weights_load(o.policy.c_str(), &s.weights, err, sizeof err) != POURSIM_OK) {
      std::fprintf(stderr, "host_sim: bad policy: %s\n", err);
      return 2;
    }
    s.cfg.tau_max = s.weights.tau_max_mnm * 1e-3;
  }
  const double tau_policy = s.cfg.tau_max;
  if (!o.config_path.empty() && poursim_config_load(o.config_path.c_str(), &s.cfg, err, sizeof err) != POURSIM_OK) {
    std::fprintf(stderr, "host_sim: bad config: %s\n", err);
    return 2;
  }
  for (const std::string &set : o.sets) {
    size_t eq = set.find('=');
    if (eq == std::string::npos) return usage_error("--set wants KEY=VALUE, got '%s'", set.c_str());
    const std::string key = set.substr(0, eq), value = set.substr(eq + 1);
    // A key of the world's config, else one of the reward that makes the figures' return.
    const bool world_key = poursim_config_key_info(key.c_str(), nullptr, nullptr, nullptr, nullptr, nullptr, nullptr) ==
                           POURSIM_OK;
    if ((world_key ? poursim_config_set(&s.cfg, key.c_str(), value.c_str(), err, sizeof err)
                   : poursim_reward_set(&s.reward, key.c_str(), value.c_str(), err, sizeof err)) != POURSIM_OK) {
      std::fprintf(stderr, "host_sim: bad --set: %s%s\n", err, key_hint(key).c_str());
      return 2;
    }
  }
  if (poursim_config_validate(&s.cfg, err, sizeof err) != POURSIM_OK) {
    std::fprintf(stderr, "host_sim: bad config: %s\n", err);
    return 2;
  }
  if (!o.policy.empty() && std::fabs(s.cfg.tau_max - tau_policy) > 1e-9) {
    std::fprintf(stderr,
                 "host_sim: mismatch: %s was trained with tau_max %.3f N·m (POUR_WEIGHTS_TAU_MAX_MNM) but the config "
                 "sets tau_max = %.3f\n",
                 o.policy.c_str(), tau_policy, s.cfg.tau_max);
    return 2;
  }
  return -1;
}

// Where --render writes: the animation, its .png snapshot and its .json trajectory, and the program that
// draws them.
struct RenderPlan {
  std::string base, json, renderer;
};

// Every output checked before any work: none may name an input or another output, all must be writable.
// -1 when all is well, else the exit status.
int check_run_outputs(const Options &o, RenderPlan &render) {
  std::vector<poursim::NamedPath> outputs;
  if (!o.csv.empty()) outputs.push_back({"--csv", o.csv});
  if (!o.render.empty()) {
    std::string ext = o.render.size() > 4 ? o.render.substr(o.render.size() - 4) : "";
    if (ext != ".gif" && ext != ".mp4") return usage_error("--render wants a .gif or .mp4 file name, got '%s'", o.render.c_str());
    render.base = o.render.substr(0, o.render.size() - 4);
    if (render.base.empty() || render.base.back() == '/')
      return usage_error("--render wants a file name before its .gif or .mp4, got '%s'", o.render.c_str());
    if (ext == ".mp4" && poursim::find_program("ffmpeg").empty()) {
      std::fprintf(stderr, "host_sim: --render %s: an MP4 needs ffmpeg on PATH (apt install ffmpeg); use a .gif\n",
                   o.render.c_str());
      return 2;
    }
    render.renderer = poursim::find_program(poursim::renderer_name());
    if (render.renderer.empty()) {
      std::fprintf(stderr,
                   "host_sim: --render needs the renderer '%s', which is not an executable%s (put the venv's bin, "
                   "e.g. .venv/bin, on PATH, or set POUR_RENDER to the program)\n",
                   poursim::renderer_name(), std::strchr(poursim::renderer_name(), '/') != nullptr ? "" : " on PATH");
      return 2;
    }
    render.json = render.base + ".json";
    outputs.push_back({"--render", o.render});
    outputs.push_back({"--render (its .png snapshot)", render.base + ".png"});
    outputs.push_back({"--render (its .json trajectory)", render.json});
  }
  std::string why;
  if (!poursim::check_outputs(outputs, {{"--policy", o.policy}, {"--config", o.config_path}}, &why))
    return usage_error("%s", why.c_str());
  return -1;
}

// What drives the bucket: pour_controller over LCM, the firmware core in-process, or a baseline. *lcm is the
// LCM controller when it is one. -1 when all is well, else the exit status.
int make_run_controller(const Options &o, const Setup &s, std::unique_ptr<poursim::Controller> &ctl,
                        poursim::LcmController **lcm) {
  *lcm = nullptr;
  if (o.lcm) {
    std::vector<double> truth_w(POURSIM_N_FEATURES * POURSIM_MAX_ACTIONS), truth_levels(POURSIM_MAX_ACTIONS);
    poursim::LcmLinkDef def;
    def.url = o.lcm_url;
    def.lockstep = !o.realtime;
    def.answer_timeout_ms = o.lcm_timeout_ms;
    if (!o.policy.empty()) {
      def.expected_weights_hash = s.weights.content_hash;
      def.truth_obs = true;
      poursim_weights_float_policy(&s.weights, truth_w.data(), truth_levels.data(), &def.truth_norm);
    }
    std::string lerr;
    std::unique_ptr<poursim::LcmController> lc = poursim::LcmController::open(def, &lerr);
    if (!lc) {
      std::fprintf(stderr, "host_sim: %s\n", lerr.c_str());
      return 1;
    }
    *lcm = lc.get();
    ctl = std::move(lc);
  } else if (!o.policy.empty()) ctl = poursim::make_firmware_controller(s.weights, o.sampled, s.cfg, o.core_reset);
  else if (o.baseline == "rate") ctl = poursim::make_rate_controller(o.rate, s.cfg);
  else if (o.baseline == "full") ctl = poursim::make_full_torque_controller(s.cfg);
  else ctl = poursim::make_hand_controller(s.cfg);
  return -1;
}

// What the episodes leave: each one's figures, the full drive's figures of each (drive = 1), and the first
// episode's recording for --render.
struct RunRecord {
  std::vector<poursim::Episode> eps;
  std::vector<poursim_drive_telemetry_t> drive;
  poursim::Recorder first;
};

// The episodes, seeds seed0, seed0 + 1, ..., each printed unless --quiet and its steps written to csv (if
// any). -1 when all ran, else the exit status.
int run_episodes(const Options &o, const Setup &s, poursim_world_t *world, poursim::Controller &ctl,
                 poursim::LcmController *lcm, uint32_t seed0, std::FILE *per, std::FILE *csv, RunRecord &run) {
  for (int k = 0; k < o.episodes; ++k) {
    uint32_t seed = seed0 + static_cast<uint32_t>(k);
    poursim::Recorder rec;
    rec.steps = !o.csv.empty() || (k == 0 && !o.render.empty());
    rec.frame_every = (k == 0 && !o.render.empty()) ? kFrameEverySteps : 0;
    poursim::Episode e = poursim::run_episode(world, ctl, seed, s.reward, &rec);
    if (!e.error.empty()) {
      int status = 1;
      if (lcm != nullptr && lcm->failed()) {
        std::fprintf(stderr, "host_sim: %s\n", e.error.c_str());
        std::fprintf(stderr, "host_sim: %s\n", lcm->link().summary().c_str());
        status = lcm->failure_status();
      } else {
        std::fprintf(stderr, "host_sim: seed %u: %s\n", seed, e.error.c_str());
      }
      return status;
    }
    run.eps.push_back(e);
    poursim_drive_telemetry_t tel;
    poursim_drive_telemetry(world, &tel);
    run.drive.push_back(tel);
    if (!o.quiet) poursim::print_episode(per, k + 1, e);
    if (csv != nullptr) poursim::write_csv_episode(csv, k + 1, seed, rec.samples, s.cfg.tau_max);
    if (k == 0 && !o.render.empty()) run.first = std::move(rec);
  }
  return -1;
}

// The summary (stdout), the drive's and the LCM link's figures, then the CSV renamed into place and the
// render drawn. The exit status: 0, or 1 when an output could not be written.
int report_run(const Options &o, const Setup &s, poursim_world_t *world, const poursim::Controller &ctl,
               poursim::LcmController *lcm, uint32_t seed0, std::FILE *per, poursim::AtomicFile *csv_file,
               const RenderPlan &render, const RunRecord &run) {
  poursim::print_summary(stdout, o.json, ctl.name(), seed0, s.cfg.tau_max, run.eps,
                         s.cfg.drive == 1 ? &run.drive : nullptr);
  if (s.cfg.drive == 1) {
    const poursim_drive_telemetry_t w = poursim::drive_worst(run.drive);
    std::fprintf(per, "drive (field-oriented, docs/motor.md): peak phase current %.1f A, peak bus %.2f V (lowest %.2f V), "
                 "faults %s\n",
                 w.peak_current, w.peak_vbus, w.min_vbus, poursim::drive_fault_names(w.faults).c_str());
  }
  if (lcm != nullptr) {
    lcm->link().drain(50);
    std::fprintf(per, "%s\n", lcm->link().summary().c_str());
  }
  int status = 0;
  std::string why;
  if (csv_file != nullptr) {
    if (!csv_file->commit(&why)) {
      std::fprintf(stderr, "host_sim: %s\n", why.c_str());
      status = 1;
    } else if (!o.quiet) {
      std::fprintf(per, "trajectory: %s\n", o.csv.c_str());
    }
  }
  if (!o.render.empty()) {
    if (!poursim::save_render_json(render.json, *poursim_world_config(world), run.first, ctl.name(), run.eps[0].m,
                                   &why)) {
      std::fprintf(stderr, "host_sim: %s\n", why.c_str());
      status = 1;
    } else if (poursim::run_render(render.renderer, render.json, o.render) != 0) {
      status = 1;
    } else if (!o.quiet) {
      std::fprintf(per, "render: %s and %s.png (trajectory %s)\n", o.render.c_str(), render.base.c_str(),
                   render.json.c_str());
    }
  }
  return status;
}

} // namespace

int main(int argc, char **argv) {
  Options o;
  int rc = parse_args(argc, argv, o);
  if (rc >= 0) return rc;
  Setup s;
  if ((rc = load_setup(o, s)) >= 0) return rc;
  if (o.bench) return poursim::run_bench(s.cfg, o.policy, o.episodes);
  if (!o.experiment.empty()) return run_experiment_cli(o, s.cfg);
  RenderPlan render;
  if ((rc = check_run_outputs(o, render)) >= 0) return rc;
  std::unique_ptr<poursim::Controller> ctl;
  poursim::LcmController *lcm = nullptr;
  if ((rc = make_run_controller(o, s, ctl, &lcm)) >= 0) return rc;

  char err[POURSIM_ERR_LEN];
  poursim_world_t *world = poursim_create(&s.cfg, err, sizeof err);
  if (world == nullptr) {
    std::fprintf(stderr, "host_sim: %s\n", err);
    return 1;
  }
  if (lcm != nullptr) lcm->set_world(world);
  const uint32_t seed0 = o.seed >= 0 ? static_cast<uint32_t>(o.seed) : s.cfg.seed;
  std::FILE *per = o.json ? stderr : stdout;
  if (!o.quiet)
    std::fprintf(per, "host_sim: %s, %d episode%s of %.1f s, tau_max %.1f N·m, seed %u\n", ctl->name().c_str(),
                 o.episodes, o.episodes > 1 ? "s" : "", s.cfg.episode_s, s.cfg.tau_max, seed0);
  // Written beside the target and renamed at the end: an existing CSV stays whole until the new one is.
  poursim::AtomicFile csv_file;
  std::FILE *csv = nullptr;
  if (!o.csv.empty()) {
    std::string why;
    if (!csv_file.open(o.csv, &why)) {
      std::fprintf(stderr, "host_sim: %s\n", why.c_str());
      poursim_destroy(world);
      return 1;
    }
    csv = csv_file.stream();
    poursim::write_csv_header(csv);
  }
  RunRecord run;
  rc = run_episodes(o, s, world, *ctl, lcm, seed0, per, csv, run);
  if (rc < 0) rc = report_run(o, s, world, *ctl, lcm, seed0, per, csv != nullptr ? &csv_file : nullptr, render, run);
  poursim_destroy(world);
  return rc;
}
