/* SPDX-License-Identifier: MIT */
/* can_bridge: joins LCM and a SocketCAN bus, so that host_sim (and lcm-spy) see a controller that sits on
 * CAN as if it spoke LCM. POUR_SENSORS/POUR_COMMAND go out as frames; Torque and Heartbeat frames come back
 * as POUR_TORQUE and POUR_STATUS. The mapping is bridge.c; this file only moves bytes. */
#include <errno.h>
#include <getopt.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "bridge.h"
#include "pour_lcm/channels.h"

static volatile sig_atomic_t g_stop = 0;

static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

typedef struct {
  pour_bridge_t bridge;
  lcm_t *lcm;
  int fd;
  int64_t lcm_dropped;
  int64_t can_tx_errors;
} app_t;

static int64_t wall_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (int64_t)ts.tv_sec * 1000000LL + ts.tv_nsec / 1000;
}

static void send_frames(app_t *app, const pour_can_frame_t *frames, int n) {
  for (int i = 0; i < n; ++i) {
    struct can_frame cf;
    memset(&cf, 0, sizeof cf);
    cf.can_id = frames[i].id;
    cf.can_dlc = frames[i].dlc;
    memcpy(cf.data, frames[i].data, frames[i].dlc);
    if (write(app->fd, &cf, sizeof cf) != (ssize_t)sizeof cf) {
      app->can_tx_errors++;
    }
  }
}

static void on_sensors(const lcm_recv_buf_t *rbuf, const char *channel, void *user) {
  (void)channel;
  app_t *app = user;
  pour_sensor_sample_t msg;
  const int n = pour_sensor_sample_t_decode(rbuf->data, 0, (int)rbuf->data_size, &msg);
  if (n < 0 || (uint32_t)n != rbuf->data_size) {
    app->lcm_dropped++;
    return;
  }
  pour_can_frame_t frame[1];
  const char *why = NULL;
  const int k = pour_bridge_from_sensors(&app->bridge, &msg, frame, &why);
  if (k == 0 && app->bridge.counters.states_refused == 1) {
    /* Once: a sender that gets one reading wrong usually gets them all wrong. */
    fprintf(stderr,
            "can_bridge: " POUR_LCM_CHANNEL_SENSORS " seq %lld not sent: %s (encoder %ld, scales %ld g, %ld g); "
            "further refusals are only counted\n",
            (long long)msg.seq, why, (long)msg.encoder, (long)msg.scale_rotating_g, (long)msg.scale_target_g);
  }
  send_frames(app, frame, k);
  pour_sensor_sample_t_decode_cleanup(&msg);
}

static void on_command(const lcm_recv_buf_t *rbuf, const char *channel, void *user) {
  (void)channel;
  app_t *app = user;
  pour_command_t msg;
  if (pour_command_t_decode(rbuf->data, 0, (int)rbuf->data_size, &msg) < 0) {
    app->lcm_dropped++;
    return;
  }
  pour_can_frame_t frames[4];
  send_frames(app, frames, pour_bridge_from_command(&app->bridge, &msg, frames));
  pour_command_t_decode_cleanup(&msg);
}

static void drain_can(app_t *app) {
  for (;;) {
    struct can_frame cf;
    const ssize_t n = recv(app->fd, &cf, sizeof cf, MSG_DONTWAIT);
    if (n != (ssize_t)sizeof cf) {
      return;
    }
    if ((cf.can_id & (CAN_ERR_FLAG | CAN_RTR_FLAG | CAN_EFF_FLAG)) != 0u || cf.can_dlc > 8u) {
      continue; /* not a frame of this protocol */
    }
    pour_can_frame_t f;
    f.id = (uint16_t)(cf.can_id & CAN_SFF_MASK);
    f.dlc = cf.can_dlc;
    memcpy(f.data, cf.data, sizeof f.data);
    pour_torque_t torque;
    pour_controller_status_t status;
    switch (pour_bridge_from_frame(&app->bridge, &f, wall_us(), &torque, &status)) {
      case POUR_BRIDGE_TORQUE: pour_torque_t_publish(app->lcm, POUR_LCM_CHANNEL_TORQUE, &torque); break;
      case POUR_BRIDGE_STATUS: pour_controller_status_t_publish(app->lcm, POUR_LCM_CHANNEL_STATUS, &status); break;
      default: break;
    }
  }
}

static int open_can(const char *iface) {
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) {
    fprintf(stderr, "can_bridge: cannot open a CAN socket (%s); this kernel may have no CAN support\n",
            strerror(errno));
    return -1;
  }
  const unsigned ifindex = if_nametoindex(iface);
  struct sockaddr_can addr;
  memset(&addr, 0, sizeof addr);
  addr.can_family = AF_CAN;
  addr.can_ifindex = (int)ifindex;
  if (ifindex == 0u || bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
    fprintf(stderr, "can_bridge: no such CAN interface '%s' (%s)\n", iface, strerror(errno));
    close(fd);
    return -1;
  }
  return fd;
}

static int parse_long(const char *opt, const char *s, long lo, long hi, long *out) {
  char *end = NULL;
  errno = 0;
  const long v = s != NULL ? strtol(s, &end, 10) : 0; /* decimal, as everywhere: 010 is 10 */
  if (s == NULL || end == s || *end != '\0' || errno != 0 || v < lo || v > hi) {
    fprintf(stderr, "can_bridge: %s needs an integer in [%ld, %ld], got '%s'\n", opt, lo, hi, s != NULL ? s : "(nothing)");
    return -1;
  }
  *out = v;
  return 0;
}

static void usage(FILE *f) {
  fprintf(f, "usage: can_bridge --channel CHANNEL [--interface socketcan] [--lcm URL] [--node N] [--n-actions A]\n"
             "                  [--duration S]\n"
             "  --channel, --interface: the SocketCAN interface (vcan0, can0) and the backend, as python-can and\n"
             "  pour-bench name them; socketcan is the only backend\n"
             "  POUR_SENSORS, POUR_COMMAND (LCM) -> Sensors, Estop, Stop, ClearErrors, Reset (CAN, can/pour.dbc)\n"
             "  Torque, Heartbeat (CAN)        -> POUR_TORQUE, POUR_STATUS (LCM)\n"
             "  the torque scale [N.m] and policy hash come from the controller's Identity frame\n"
             "  defaults: LCM %s, node 0, 11 actions (the length of POUR_TORQUE's probabilities)\n"
             "  numbers are decimal (--node 010 is node 10); --key VALUE or --key=VALUE\n"
             "  --help, --version: this text; the version\n"
             "exit status (the same meanings in every pour program): 0 done; 1 a failure while running (the\n"
             "CAN interface or LCM cannot be opened, or fails while bridging); 2 bad command line\n",
          POUR_LCM_DEFAULT_URL);
}

int main(int argc, char **argv) {
  const char *iface = NULL;
  const char *url = NULL;
  long duration_s = 0;
  pour_bridge_config_t cfg = pour_bridge_default_config();
  enum { OPT_CHANNEL = 256, OPT_INTERFACE, OPT_IFACE, OPT_LCM, OPT_NODE, OPT_N_ACTIONS, OPT_DURATION, OPT_VERSION };
  static const struct option options[] = {
      {"help", no_argument, NULL, 'h'},
      {"version", no_argument, NULL, OPT_VERSION},
      {"channel", required_argument, NULL, OPT_CHANNEL},
      {"interface", required_argument, NULL, OPT_INTERFACE},
      {"iface", required_argument, NULL, OPT_IFACE},
      {"lcm", required_argument, NULL, OPT_LCM},
      {"node", required_argument, NULL, OPT_NODE},
      {"n-actions", required_argument, NULL, OPT_N_ACTIONS},
      {"duration", required_argument, NULL, OPT_DURATION},
      {NULL, 0, NULL, 0},
  };
  opterr = 0; /* our own messages */
  int opt;
  while ((opt = getopt_long(argc, argv, "+:h", options, NULL)) != -1) {
    const char *a = argv[optind - 1];
    long n = 0;
    switch (opt) {
    case 'h':
      usage(stdout);
      return 0;
    case OPT_VERSION:
      printf("can_bridge %s\n", POUR_VERSION);
      return 0;
    case OPT_CHANNEL:
      iface = optarg;
      break;
    case OPT_INTERFACE:
      if (strcmp(optarg, "socketcan") != 0) {
        fprintf(stderr, "can_bridge: --interface '%s': only socketcan is supported\n", optarg);
        return 2;
      }
      break;
    case OPT_IFACE:
      fprintf(stderr, "can_bridge: --iface is now --channel (python-can's name): --channel %s\n", optarg);
      return 2;
    case OPT_LCM:
      url = optarg;
      break;
    case OPT_NODE:
      if (parse_long("--node", optarg, 0, POUR_CAN_NODE_ID_MAX, &n) != 0) return 2;
      cfg.node_id = (uint8_t)n;
      break;
    case OPT_N_ACTIONS:
      if (parse_long("--n-actions", optarg, 2, 16, &n) != 0) return 2;
      cfg.n_actions = (uint8_t)n;
      break;
    case OPT_DURATION:
      if (parse_long("--duration", optarg, 1, 10000000, &duration_s) != 0) return 2;
      break;
    case ':':
      fprintf(stderr, "can_bridge: %s needs a value (see --help)\n", a);
      return 2;
    default:
      fprintf(stderr, "can_bridge: unknown option '%s' (see --help)\n", a);
      return 2;
    }
  }
  if (optind < argc) {
    fprintf(stderr, "can_bridge: unexpected argument '%s' (see --help)\n", argv[optind]);
    return 2;
  }
  if (iface == NULL) {
    fprintf(stderr, "can_bridge: --channel CHANNEL is required (e.g. --channel vcan0)\n");
    return 2;
  }
  static app_t app;
  if (pour_bridge_init(&app.bridge, &cfg) != POUR_OK) {
    fprintf(stderr, "can_bridge: bad configuration\n");
    return 2;
  }
  app.fd = open_can(iface);
  if (app.fd < 0) {
    return 1;
  }
  app.lcm = lcm_create(url != NULL ? url : POUR_LCM_DEFAULT_URL);
  if (app.lcm == NULL) {
    fprintf(stderr, "can_bridge: cannot open LCM at %s\n", url != NULL ? url : POUR_LCM_DEFAULT_URL);
    close(app.fd);
    return 1;
  }
  lcm_subscribe(app.lcm, POUR_LCM_CHANNEL_SENSORS, on_sensors, &app);
  lcm_subscribe(app.lcm, POUR_LCM_CHANNEL_COMMAND, on_command, &app);

  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  fprintf(stderr, "can_bridge: %s node %u <-> LCM %s\n", iface, (unsigned)cfg.node_id,
          url != NULL ? url : POUR_LCM_DEFAULT_URL);

  struct timespec t0;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  int rc = 0;
  while (!g_stop) {
    struct pollfd p[2] = {{.fd = lcm_get_fileno(app.lcm), .events = POLLIN, .revents = 0},
                          {.fd = app.fd, .events = POLLIN, .revents = 0}};
    const int r = poll(p, 2, 100);
    if (r < 0 && errno != EINTR) {
      fprintf(stderr, "can_bridge: poll failed (%s)\n", strerror(errno));
      rc = 1;
      break;
    }
    if (r > 0 && (p[1].revents & POLLIN) != 0) {
      drain_can(&app);
    }
    if (r > 0 && (p[0].revents & POLLIN) != 0 && lcm_handle(app.lcm) != 0) {
      fprintf(stderr, "can_bridge: LCM receive failed\n");
      rc = 1;
      break;
    }
    if (duration_s > 0) {
      struct timespec now;
      clock_gettime(CLOCK_MONOTONIC, &now);
      if (now.tv_sec - t0.tv_sec >= duration_s) {
        break;
      }
    }
  }
  const pour_bridge_counters_t *c = &app.bridge.counters;
  printf("can_bridge: states %lld refused %lld torques %lld unmatched %lld heartbeats %lld identities %lld "
         "frames_dropped %lld commands %lld lcm_dropped %lld can_tx_errors %lld\n",
         (long long)c->states_sent, (long long)c->states_refused, (long long)c->torques,
         (long long)c->torques_unmatched, (long long)c->heartbeats, (long long)c->identities, (long long)c->frames_dropped,
         (long long)c->commands, (long long)app.lcm_dropped, (long long)app.can_tx_errors);
  lcm_destroy(app.lcm);
  close(app.fd);
  return rc;
}
