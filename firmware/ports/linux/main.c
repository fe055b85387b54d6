/* SPDX-License-Identifier: MIT */
/* pour_controller: the firmware core as a Linux process, talking to host_sim (or a bench) over a
 * transport chosen with --io. */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "controller.h"
#include "io_lcm.h"
#include "io_socketcan.h"
#ifdef POUR_SIM_DRIVE
#include "sim_drive.h"
#endif
#include "pour/faults.h"
#include "pour/weights_compiled.h"

static volatile sig_atomic_t g_stop = 0;

static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

static void usage(FILE *f) {
  fprintf(f,
          "usage: pour_controller [options]\n"
          "  --io lcm[:URL]         transport (default lcm with its default URL)\n"
          "  --io can:IFACE[,node=N][,heartbeat-ms=N][,watchdog-ms=N]\n"
          "                         SocketCAN, the protocol of can/pour.dbc (defaults 0, 100, 50)\n"
          "                         [,params=FILE]: parameters loaded from FILE at start, saved there on\n"
          "                         ParamSave (pour-bench config save); it overrides node= and the options\n"
          "  --lcm URL              the same as --io lcm:URL (the LCM URL's flag in every pour program)\n"
          "  --channel CHANNEL [--node N] [--interface socketcan]\n"
          "                         the same as --io can:CHANNEL[,node=N] (python-can's and pour-bench's names)\n"
          "  --lockstep             one tick per sensor sample (deterministic: what host_sim --lcm runs\n"
          "                         unless --realtime)\n"
          "  --stall-ms N           lockstep: tick at 1 kHz on stale input after N ms without a sample (2000)\n"
          "  --duration S           stop after S seconds (default: run until SIGINT/SIGTERM)\n"
          "  --max-states N         stop after answering N sensor samples\n"
          "  --input-timeout-ms N   the core's input timeout (default from the core)\n"
          "  --encoder-bits N       resolution of the rig's absolute encoder, %u .. %u (default %u; host_sim's\n"
          "                         encoder_bits must match)\n"
          "  --sampled              sample actions instead of the greedy argmax\n"
          "  --seed N               seed of the sampled mode\n"
          "  --verbose              a status line on stderr every 100 ms\n"
          "  --help, --version      this text; the version and the compiled-in weights' hash\n"
          "Options take their value as --key VALUE or --key=VALUE.\n"
          "Weights: the weights.h named by CMake's POUR_WEIGHTS (compiled in, hash 0x%08x).\n"
          "Exit status (the same meanings in every pour program): 0 done; 1 a failure while running (the\n"
          "transport cannot be opened, the core refuses its configuration); 2 bad command line (an unknown\n"
          "option or a bad value, --io's included). Numbers are decimal: node=010 is node 10.\n",
          (unsigned)POUR_ENCODER_BITS_MIN, (unsigned)POUR_ENCODER_BITS_MAX,
          (unsigned)pour_sensors_default_config().encoder_bits, (unsigned)pour_weights_compiled.content_hash);
}

/* Parses a whole decimal integer in [lo, hi]; prints a message naming the option otherwise. */
static int parse_int(const char *opt, const char *s, long long lo, long long hi, long long *out) {
  char *end = NULL;
  errno = 0;
  const long long v = s != NULL ? strtoll(s, &end, 10) : 0;
  if (s == NULL || end == s || *end != '\0' || errno != 0 || v < lo || v > hi) {
    fprintf(stderr, "pour_controller: %s needs an integer in [%lld, %lld], got '%s'\n", opt, lo, hi,
            s != NULL ? s : "(nothing)");
    return -1;
  }
  *out = v;
  return 0;
}

static int parse_seconds(const char *opt, const char *s, long long *out_ms) {
  char *end = NULL;
  errno = 0;
  const double v = s != NULL ? strtod(s, &end) : 0.0;
  if (s == NULL || end == s || *end != '\0' || errno != 0 || !(v > 0.0) || v > 1e7) {
    fprintf(stderr, "pour_controller: %s needs a number of seconds in (0, 1e7], got '%s'\n", opt,
            s != NULL ? s : "(nothing)");
    return -1;
  }
  *out_ms = (long long)(v * 1000.0 + 0.5);
  if (*out_ms < 1) {
    *out_ms = 1;
  }
  return 0;
}

/* Opens the transport named by spec: "lcm", "lcm:URL" or "can:IFACE[,...]". Other backends add a branch here.
 * Returns 0, -2 for a spec that does not parse (a command-line error), -1 if the transport cannot open. */
static int open_io(const char *spec, pour_io_t *io, pour_linux_config_t *cfg) {
  if (strcmp(spec, "lcm") == 0) {
    return pour_io_lcm_open(io, NULL);
  }
  if (strncmp(spec, "lcm:", 4) == 0) {
    return pour_io_lcm_open(io, spec + 4);
  }
  if (strncmp(spec, "can:", 4) == 0) {
    pour_io_socketcan_config_t can = {.node = pour_can_node_default_config()};
    can.node.identity.weights_hash = cfg->weights->content_hash;
    can.node.identity.tau_max_cnm = (uint16_t)(cfg->weights->tau_max_mnm / 10);
    /* In lockstep the loop itself waits stall_ms before it treats silence as stale input. */
    can.watchdog_grace_ms = cfg->lockstep ? (uint32_t)cfg->stall_ms : 0u;
    if (pour_io_socketcan_parse(spec + 4, &can) != 0) {
      return -2;
    }
    if (can.sim_drive) {
#ifdef POUR_SIM_DRIVE
      can.drive_open = pour_sim_drive_open;
      can.drive_tick = pour_sim_drive_tick;
#else
      fprintf(stderr, "pour_controller: drive=sim needs the simulated drive, which this build leaves out: run "
                      "pour_controller_sim (the same controller with host_sim's motor model linked in)\n");
      return -2;
#endif
    }
    return pour_io_socketcan_load_params(&can, &cfg->control, cfg->weights) == 0 ? pour_io_socketcan_open(io, &can) : -1;
  }
  fprintf(stderr, "pour_controller: unknown transport '%s' (known: lcm[:URL], can:IFACE)\n", spec);
  return -2;
}

/* Long options; the values of `val` past the ASCII range name the ones without a short form. */
enum {
  OPT_IO = 256, OPT_LCM, OPT_CHANNEL, OPT_INTERFACE, OPT_IFACE, OPT_NODE, OPT_LOCKSTEP, OPT_STALL_MS, OPT_DURATION, OPT_MAX_STATES,
  OPT_INPUT_TIMEOUT_MS, OPT_ENCODER_BITS, OPT_SAMPLED, OPT_SEED, OPT_VERBOSE, OPT_VERSION
};

static const struct option kOptions[] = {
    {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, OPT_VERSION},
    {"io", required_argument, NULL, OPT_IO},
    {"lcm", required_argument, NULL, OPT_LCM},
    {"channel", required_argument, NULL, OPT_CHANNEL},
    {"interface", required_argument, NULL, OPT_INTERFACE},
    {"iface", required_argument, NULL, OPT_IFACE},
    {"node", required_argument, NULL, OPT_NODE},
    {"lockstep", no_argument, NULL, OPT_LOCKSTEP},
    {"stall-ms", required_argument, NULL, OPT_STALL_MS},
    {"duration", required_argument, NULL, OPT_DURATION},
    {"max-states", required_argument, NULL, OPT_MAX_STATES},
    {"input-timeout-ms", required_argument, NULL, OPT_INPUT_TIMEOUT_MS},
    {"encoder-bits", required_argument, NULL, OPT_ENCODER_BITS},
    {"sampled", no_argument, NULL, OPT_SAMPLED},
    {"seed", required_argument, NULL, OPT_SEED},
    {"verbose", no_argument, NULL, OPT_VERBOSE},
    {NULL, 0, NULL, 0},
};

int main(int argc, char **argv) {
  pour_linux_config_t cfg = pour_linux_default_config();
  cfg.weights = &pour_weights_compiled;
  const char *io_spec = "lcm";
  const char *iface = NULL, *node = NULL;
  char spec_buf[256];
  opterr = 0; /* our own messages, in the words of the other pour programs */
  int c;
  while ((c = getopt_long(argc, argv, "+:h", kOptions, NULL)) != -1) {
    long long n = 0;
    const char *a = argv[optind - 1];
    switch (c) {
    case 'h':
      usage(stdout);
      return 0;
    case OPT_VERSION:
      printf("pour_controller %s, weights hash 0x%08x\n", POUR_VERSION, (unsigned)pour_weights_compiled.content_hash);
      return 0;
    case OPT_IO:
      io_spec = optarg;
      break;
    case OPT_LCM:
      if (snprintf(spec_buf, sizeof spec_buf, "lcm:%s", optarg) >= (int)sizeof spec_buf) {
        fprintf(stderr, "pour_controller: --lcm: the URL is longer than %u characters\n", (unsigned)sizeof spec_buf - 5u);
        return 2;
      }
      io_spec = spec_buf;
      break;
    case OPT_CHANNEL:
      iface = optarg;
      break;
    case OPT_INTERFACE:
      if (strcmp(optarg, "socketcan") != 0) {
        fprintf(stderr, "pour_controller: --interface '%s': only socketcan is supported\n", optarg);
        return 2;
      }
      break;
    case OPT_IFACE:
      fprintf(stderr, "pour_controller: --iface is now --channel (python-can's name): --channel %s\n", optarg);
      return 2;
    case OPT_NODE:
      node = optarg;
      break;
    case OPT_LOCKSTEP:
      cfg.lockstep = true;
      break;
    case OPT_STALL_MS:
      if (parse_int("--stall-ms", optarg, 1, 3600000, &n) != 0) {
        return 2;
      }
      cfg.stall_ms = n;
      break;
    case OPT_DURATION:
      if (parse_seconds("--duration", optarg, &n) != 0) {
        return 2;
      }
      cfg.duration_ms = n;
      break;
    case OPT_MAX_STATES:
      if (parse_int("--max-states", optarg, 1, INT64_MAX, &n) != 0) {
        return 2;
      }
      cfg.max_states = n;
      break;
    case OPT_INPUT_TIMEOUT_MS:
      if (parse_int("--input-timeout-ms", optarg, 1, UINT16_MAX, &n) != 0) {
        return 2;
      }
      cfg.control.input_timeout_ms = (uint16_t)n;
      break;
    case OPT_ENCODER_BITS:
      if (parse_int("--encoder-bits", optarg, POUR_ENCODER_BITS_MIN, POUR_ENCODER_BITS_MAX, &n) != 0) {
        return 2;
      }
      cfg.control.sensors.encoder_bits = (uint8_t)n;
      break;
    case OPT_SAMPLED:
      cfg.control.policy_mode = POUR_POLICY_SAMPLED;
      break;
    case OPT_SEED:
      if (parse_int("--seed", optarg, 0, UINT32_MAX, &n) != 0) {
        return 2;
      }
      cfg.control.seed = (uint32_t)n;
      break;
    case OPT_VERBOSE:
      cfg.verbose = true;
      break;
    case ':':
      fprintf(stderr, "pour_controller: %s needs a value (see --help)\n", a);
      return 2;
    default:
      fprintf(stderr, "pour_controller: unknown option '%s' (see --help)\n", a);
      return 2;
    }
  }
  if (optind < argc) {
    fprintf(stderr, "pour_controller: unexpected argument '%s' (see --help)\n", argv[optind]);
    return 2;
  }
  if (node != NULL && iface == NULL) {
    fprintf(stderr, "pour_controller: --node goes with --channel CHANNEL\n");
    return 2;
  }
  if (iface != NULL) {
    const int len = node != NULL ? snprintf(spec_buf, sizeof spec_buf, "can:%s,node=%s", iface, node)
                                 : snprintf(spec_buf, sizeof spec_buf, "can:%s", iface);
    if (len >= (int)sizeof spec_buf) {
      fprintf(stderr, "pour_controller: --channel/--node: longer than %u characters\n", (unsigned)sizeof spec_buf - 1u);
      return 2;
    }
    io_spec = spec_buf;
  }

  pour_io_t io;
  memset(&io, 0, sizeof io);
  const int opened = open_io(io_spec, &io, &cfg);
  if (opened != 0) {
    return opened == -2 ? 2 : 1;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);

  fprintf(stderr, "pour_controller: %s, io %s, weights hash 0x%08x\n",
          cfg.lockstep ? "lockstep" : "real time 1 kHz", io_spec, (unsigned)cfg.weights->content_hash);
  pour_linux_stats_t st;
  const int rc = pour_linux_run(&cfg, &io, &g_stop, &st);
  io.close(&io);
  if (rc != 0) {
    fprintf(stderr, "pour_controller: the core refused its configuration: %s\n",
            pour_status_name((pour_status_t)rc));
    return 1;
  }
  char faults_text[POUR_FAULTS_TEXT_MAX];
  printf("pour_controller: ticks %lld states %lld answers %lld duplicates %lld dropped %lld stale_ticks %lld "
         "overruns %lld late_mean_us %.1f late_max_us %lld step_max_ns %lld io_errors %lld resets %lld "
         "mode %s faults %s (0x%04x) brake_engagements %lld power_cuts %lld\n",
         (long long)st.ticks, (long long)st.states_received, (long long)st.answers, (long long)st.duplicates,
         (long long)st.messages_dropped, (long long)st.stale_ticks, (long long)st.overruns,
         st.ticks > 0 ? (double)st.late_sum_us / (double)st.ticks : 0.0, (long long)st.late_max_us,
         (long long)st.step_time_max_ns, (long long)st.io_errors, (long long)st.resets,
         pour_mode_name(st.mode) != NULL ? pour_mode_name(st.mode) : "?",
         pour_faults_format(st.faults, faults_text, sizeof faults_text), (unsigned)st.faults, (long long)st.brake_engagements, (long long)st.power_cuts);
  return 0;
}
