/* SPDX-License-Identifier: MIT */
#include "io_socketcan.h"

#include <errno.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "params_file.h"
#include "pour/can_params.h"

typedef struct {
  int fd;
  pour_io_socketcan_config_t config;
  pour_can_node_t node;
  int64_t last_ms;          /* wall clock of the last watchdog update [ms] */
  int64_t next_heartbeat_ms;
  uint32_t dropped_reported;
  pour_control_output_t out; /* the latest output the loop told us of (what the heartbeat reports) */
  uint32_t overruns;
  pour_params_t params;      /* in force; saved on ParamSave */
  pour_control_t *ctl;       /* the core, while can_service runs (what an accepted write reconfigures) */
  bool experiment_asked;     /* an ExperimentStart went to the core: its answer comes from the next update */
  uint8_t experiment_kind;
} socketcan_t;

static socketcan_t g_can; /* one transport per process */

static int64_t mono_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000LL + ts.tv_nsec / 1000000L;
}

static int send_frame(socketcan_t *s, const pour_can_frame_t *f) {
  struct can_frame cf;
  memset(&cf, 0, sizeof cf);
  cf.can_id = f->id;
  cf.can_dlc = f->dlc;
  memcpy(cf.data, f->data, f->dlc);
  /* A full TX queue (ENOBUFS) is reported, not retried: the next tick sends fresher data anyway. */
  return write(s->fd, &cf, sizeof cf) == (ssize_t)sizeof cf ? 0 : -1;
}

/* Wall-clock housekeeping: the node's watchdog, and its heartbeat and identity frames on schedule (the
 * loop ticks only on states in lockstep, yet a bench must see the controller alive while it waits). */
static void housekeeping(socketcan_t *s) {
  const int64_t now = mono_ms();
  if (now > s->last_ms) {
    (void)pour_can_node_watchdog(&s->node, (uint32_t)(now - s->last_ms));
    s->last_ms = now;
  }
  if (now >= s->next_heartbeat_ms) {
    pour_can_frame_t f[2];
    const uint8_t n = pour_can_node_status_frames(&s->node, &s->out, s->overruns, f);
    for (uint8_t i = 0; i < n; ++i) {
      (void)send_frame(s, &f[i]);
    }
    s->next_heartbeat_ms += s->config.node.heartbeat_period_ms;
    if (s->next_heartbeat_ms <= now) {
      s->next_heartbeat_ms = now + s->config.node.heartbeat_period_ms;
    }
  }
}

/* Moves the frames waiting on the socket into the node; stops after the first sensor sample. The
 * control input itself is taken once per tick, in can_begin_tick. */
static int drain(socketcan_t *s, pour_io_input_t *in) {
  for (;;) {
    struct can_frame cf;
    const ssize_t n = recv(s->fd, &cf, sizeof cf, MSG_DONTWAIT);
    if (n < 0) {
      return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -1;
    }
    if (n != (ssize_t)sizeof cf || (cf.can_id & (CAN_ERR_FLAG | CAN_RTR_FLAG | CAN_EFF_FLAG)) != 0u ||
        cf.can_dlc > 8u) {
      /* Error, RTR, extended or FD frames: the codec never sees them, the heartbeat counts them. */
      if (s->node.counters.bad_id != UINT32_MAX) {
        s->node.counters.bad_id++;
      }
      s->dropped_reported++;
      in->n_dropped++;
      continue;
    }
    pour_can_frame_t f;
    f.id = (uint16_t)(cf.can_id & CAN_SFF_MASK);
    f.dlc = cf.can_dlc;
    memcpy(f.data, cf.data, sizeof f.data);
    if (pour_can_node_receive(&s->node, &f) != POUR_CAN_RX_OK) {
      const uint32_t d = pour_can_node_dropped(&s->node);
      in->n_dropped += d - s->dropped_reported;
      s->dropped_reported = d;
      continue;
    }
    /* This frame was a sample (a command frame must not report the one still waiting for its tick). */
    if ((f.id & POUR_CAN_CMD_MASK) == POUR_CAN_CMD_SENSORS && s->node.sensors_fresh) {
      in->n_samples++;
      in->sensors = s->node.sensors;
      in->sample_seq = (int64_t)s->node.sensors.seq; /* 32 bits, extended by the node: no wrap, no reset */
      in->sample_utime = 0; /* CAN carries no time stamp; the bridge restores it */
      in->episode = 0;
      return 1;
    }
  }
}

static int can_wait(pour_io_t *io, int64_t timeout_us, pour_io_input_t *in) {
  socketcan_t *s = io->ctx;
  const int64_t deadline = mono_ms() + (timeout_us + 999) / 1000;
  for (;;) {
    housekeeping(s); /* time passed while polling counts before a frame that arrived feeds the watchdog */
    const int r = drain(s, in);
    housekeeping(s);
    if (r != 0) {
      return r;
    }
    const int64_t now = mono_ms();
    if (now >= deadline) {
      return 0;
    }
    int64_t until = deadline < s->next_heartbeat_ms ? deadline : s->next_heartbeat_ms;
    struct pollfd p = {.fd = s->fd, .events = POLLIN, .revents = 0};
    const int64_t wait_ms = until > now ? until - now : 0;
    if (poll(&p, 1, (int)(wait_ms > 1000 ? 1000 : wait_ms)) < 0 && errno != EINTR) {
      return -1;
    }
  }
}

static void can_begin_tick(pour_io_t *io, pour_control_input_t *in) {
  socketcan_t *s = io->ctx;
  housekeeping(s);
  pour_can_node_begin_tick(&s->node, in);
  pour_params_correct(&s->params, &in->sensors);
}

static pour_status_t apply_params(void *user, const pour_params_t *candidate) {
  socketcan_t *s = user;
  return pour_params_apply(s->ctl, candidate, s->ctl->policy.weights);
}

static pour_status_t save_params(void *user, const pour_params_t *params) {
  socketcan_t *s = user;
  return pour_params_file_save(s->config.params_path, params) == 0 ? POUR_OK : POUR_EINVAL;
}

/* An ExperimentStart goes to the core before the step; the update of that step answers it, and the next
 * tick's service sends the answer (a ParamAck). */
static void serve_experiment(socketcan_t *s, pour_control_t *ctl) {
  if (s->experiment_asked) {
    s->experiment_asked = false;
    const uint8_t answer = pour_control_experiment_answer(ctl);
    pour_can_frame_t ack;
    if (pour_can_node_experiment_ack(&s->node, s->experiment_kind, answer, &ack) == POUR_OK) {
      if (answer != (uint8_t)POUR_CONTROL_EXPERIMENT_ACCEPTED) {
        fprintf(stderr, "pour_controller: experiment %u refused (ParamAck result %u)\n", (unsigned)s->experiment_kind,
                (unsigned)ack.data[2]);
      }
      (void)send_frame(s, &ack);
    }
  }
  uint8_t kind = 0u;
  if (pour_can_node_take_experiment(&s->node, &kind)) {
    pour_control_experiment(ctl, kind);
    s->experiment_asked = true;
    s->experiment_kind = kind;
  }
}

/* One parameter request per tick, answered before the step; the node id in force stays the one bound at
 * start (a new node_id takes effect at the next start). */
static void can_service(pour_io_t *io, pour_control_t *ctl) {
  socketcan_t *s = io->ctx;
  if (s->config.drive_tick != NULL) {
    (void)s->config.drive_tick(&s->node, s->out.mode);
  }
  pour_can_frame_t cal;
  if (pour_can_node_calibration_frame(&s->node, s->out.mode, &cal)) {
    (void)send_frame(s, &cal);
  }
  serve_experiment(s, ctl);
  pour_can_param_request_t r;
  if (!pour_can_node_take_param_request(&s->node, &r)) {
    return;
  }
  s->ctl = ctl;
  const pour_can_params_env_t env = {
      .writable = pour_params_writable(ctl),
      .have_sample = s->node.have_seq,
      .sample = s->node.sensors,
      .apply = apply_params,
      .save = s->config.params_path[0] != '\0' ? save_params : NULL,
      .user = s,
  };
  pour_can_frame_t reply;
  const pour_param_result_t res = pour_can_params_handle(s->config.node.node_id, &r, &s->params, &env, &reply);
  if (res != POUR_PARAM_OK) {
    fprintf(stderr, "pour_controller: parameter request 0x%02x (parameter %u) refused: %s\n", (unsigned)r.cmd,
            (unsigned)r.param_id, pour_param_result_name(res));
  }
  (void)send_frame(s, &reply);
}

static int can_send_torque(pour_io_t *io, const pour_io_answer_t *a) {
  socketcan_t *s = io->ctx;
  s->out = *a->out;
  pour_can_frame_t f;
  if (pour_can_node_torque_frame(&s->node, a->out, &f) != POUR_OK) {
    return -1;
  }
  const int rc = send_frame(s, &f);
  housekeeping(s);
  return rc;
}

static int can_send_status(pour_io_t *io, const pour_io_status_t *st) {
  socketcan_t *s = io->ctx;
  /* The heartbeat keeps its own period; the status only refreshes what it reports. */
  s->out.mode = st->mode;
  s->out.faults = st->faults;
  s->overruns = st->overruns > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)st->overruns;
  housekeeping(s);
  return 0;
}

static void can_close(pour_io_t *io) {
  socketcan_t *s = io->ctx;
  if (s->fd >= 0) {
    close(s->fd);
    s->fd = -1;
  }
}

static int parse_field(const char *what, const char *v, unsigned long max, unsigned long min, unsigned long *out) {
  char *end = NULL;
  errno = 0;
  const unsigned long n = strtoul(v, &end, 10);
  if (end == v || *end != '\0' || errno != 0 || n < min || n > max || v[0] == '-') {
    fprintf(stderr, "pour_controller: --io can: %s needs an integer in [%lu, %lu], got '%s'\n", what, min, max, v);
    return -1;
  }
  *out = n;
  return 0;
}

int pour_io_socketcan_parse(const char *spec, pour_io_socketcan_config_t *config) {
  char buf[128];
  if (spec == NULL || strlen(spec) >= sizeof buf) {
    fprintf(stderr, "pour_controller: --io can: needs IFACE[,node=N][,heartbeat-ms=N][,watchdog-ms=N][,params=FILE]"
            "[,drive=sim]\n");
    return -1;
  }
  strcpy(buf, spec);
  char *save = NULL;
  char *iface = strtok_r(buf, ",", &save);
  if (iface == NULL || strlen(iface) == 0u || strlen(iface) >= sizeof config->iface) {
    fprintf(stderr, "pour_controller: --io can: needs an interface name of 1..15 characters, got '%s'\n", spec);
    return -1;
  }
  strcpy(config->iface, iface);
  for (char *kv = strtok_r(NULL, ",", &save); kv != NULL; kv = strtok_r(NULL, ",", &save)) {
    char *eq = strchr(kv, '=');
    unsigned long n = 0;
    if (eq == NULL) {
      fprintf(stderr, "pour_controller: --io can: '%s' is not key=value\n", kv);
      return -1;
    }
    *eq = '\0';
    const char *v = eq + 1;
    if (strcmp(kv, "node") == 0) {
      if (parse_field("node", v, POUR_CAN_NODE_ID_MAX, 0, &n) != 0) {
        return -1;
      }
      config->node.node_id = (uint8_t)n;
    } else if (strcmp(kv, "heartbeat-ms") == 0) {
      if (parse_field("heartbeat-ms", v, UINT16_MAX, 1, &n) != 0) {
        return -1;
      }
      config->node.heartbeat_period_ms = (uint16_t)n;
    } else if (strcmp(kv, "watchdog-ms") == 0) {
      if (parse_field("watchdog-ms", v, UINT16_MAX, 1, &n) != 0) {
        return -1;
      }
      config->node.watchdog_ms = (uint16_t)n;
    } else if (strcmp(kv, "params") == 0) {
      if (v[0] == '\0' || strlen(v) >= sizeof config->params_path) {
        fprintf(stderr, "pour_controller: --io can: params needs a file name of 1..%zu characters\n",
                sizeof config->params_path - 1u);
        return -1;
      }
      strcpy(config->params_path, v);
    } else if (strcmp(kv, "drive") == 0) {
      if (strcmp(v, "sim") != 0) {
        fprintf(stderr, "pour_controller: --io can: drive can only be 'sim' (host_sim's motor model), got '%s'\n", v);
        return -1;
      }
      config->sim_drive = true;
    } else {
      fprintf(stderr, "pour_controller: --io can: unknown key '%s' (node, heartbeat-ms, watchdog-ms, params, drive)\n",
              kv);
      return -1;
    }
  }
  return 0;
}

int pour_io_socketcan_load_params(pour_io_socketcan_config_t *config, pour_control_config_t *control,
                                  const pour_policy_weights_t *weights) {
  pour_params_default(&config->params, control, config->node.node_id);
  if (config->params_path[0] != '\0') {
    const int rc = pour_params_file_load(config->params_path, &config->params);
    if (rc < 0) {
      return -1;
    }
    static pour_control_t trial; /* the core's own rules between parameters, before anything runs */
    const pour_status_t st = pour_control_init(&trial, &config->params.control, weights);
    if (st != POUR_OK) {
      fprintf(stderr, "pour_controller: parameter file %s: the core refuses its configuration (%s: e.g. theta_min "
              ">= theta_max, a stop torque above tau_limit); fix it with pour-bench config or delete it\n",
              config->params_path, pour_status_name(st));
      return -1;
    }
    fprintf(stderr, "pour_controller: parameters %s %s\n", rc == 0 ? "from" : "at their defaults; none yet in",
            config->params_path);
  }
  *control = config->params.control;
  config->node.node_id = config->params.node_id;
  return 0;
}

int pour_io_socketcan_open(pour_io_t *io, const pour_io_socketcan_config_t *config) {
  socketcan_t *s = &g_can;
  memset(s, 0, sizeof *s);
  s->fd = -1;
  s->config = *config;
  s->params = config->params;
  pour_can_node_config_t nc = config->node;
  const uint32_t wd = (uint32_t)nc.watchdog_ms + config->watchdog_grace_ms;
  nc.watchdog_ms = (uint16_t)(wd > UINT16_MAX ? UINT16_MAX : wd);
  if (pour_can_node_init(&s->node, &nc) != POUR_OK) {
    fprintf(stderr, "pour_controller: --io can: bad node configuration\n");
    return -1;
  }
  if (config->drive_open != NULL && config->drive_open(&s->node) != 0) {
    return -1;
  }
  s->fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (s->fd < 0) {
    fprintf(stderr, "pour_controller: --io can:%s: cannot open a CAN socket (%s); this kernel may have no CAN support\n",
            config->iface, strerror(errno));
    return -1;
  }
  const unsigned ifindex = if_nametoindex(config->iface);
  if (ifindex == 0u) {
    fprintf(stderr, "pour_controller: --io can:%s: no such CAN interface (%s)\n", config->iface, strerror(errno));
    close(s->fd);
    s->fd = -1;
    return -1;
  }
  /* Only this node's standard data frames reach us; everything else on the bus is someone else's. */
  struct can_filter filter = {
      .can_id = (canid_t)pour_can_id(config->node.node_id, 0),
      .can_mask = POUR_CAN_NODE_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG,
  };
  struct sockaddr_can addr;
  memset(&addr, 0, sizeof addr);
  addr.can_family = AF_CAN;
  addr.can_ifindex = (int)ifindex;
  if (setsockopt(s->fd, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter) < 0 ||
      bind(s->fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
    fprintf(stderr, "pour_controller: --io can:%s: cannot bind (%s)\n", config->iface, strerror(errno));
    close(s->fd);
    s->fd = -1;
    return -1;
  }
  s->last_ms = mono_ms();
  s->next_heartbeat_ms = s->last_ms;
  io->ctx = s;
  io->wait = can_wait;
  io->begin_tick = can_begin_tick;
  io->service = can_service;
  io->send_torque = can_send_torque;
  io->send_status = can_send_status;
  io->close = can_close;
  return 0;
}
