/* SPDX-License-Identifier: MIT */
#include "io_lcm.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <time.h>

#include <lcm/lcm.h>

#include "pour_command_t.h"
#include "pour_controller_status_t.h"
#include "pour_lcm/channels.h"
#include "pour_sensor_sample_t.h"
#include "pour_torque_t.h"

typedef struct {
  lcm_t *lcm;
  pour_io_input_t *in; /* the wait in progress; handlers write here */
  int got_sample;
} io_lcm_t;

/* A message counts only if it decodes completely and exactly: foreign fingerprints, truncated and
 * padded buffers are all dropped and counted. Both types are fixed-size, so decoding never allocates.
 * The readings reach the core as sent, with no conversion (the in-process simulator hands over the same
 * integers): an impossible one (a negative or too large encoder count, a scale out of range) is the
 * estimator's to refuse, which latches BAD_INPUT, rather than a message silently dropped here. */
static void on_sensors(const lcm_recv_buf_t *rbuf, const char *channel, void *user) {
  (void)channel;
  io_lcm_t *s = user;
  pour_sensor_sample_t msg;
  const int n = pour_sensor_sample_t_decode(rbuf->data, 0, (int)rbuf->data_size, &msg);
  if (n < 0 || (uint32_t)n != rbuf->data_size) {
    s->in->n_dropped++;
    return;
  }
  s->in->sensors.seq = (uint32_t)((uint64_t)msg.seq & 0xFFFFFFFFu);
  /* Two's complement: a negative count becomes one >= 2^31, which no encoder has. */
  s->in->sensors.encoder = (uint32_t)msg.encoder;
  s->in->sensors.scale_rotating_g = msg.scale_rotating_g;
  s->in->sensors.scale_target_g = msg.scale_target_g;
  s->in->sample_seq = msg.seq;
  s->in->sample_utime = msg.utime;
  s->in->episode = msg.episode;
  s->in->n_samples++;
  s->got_sample = 1;
}

static void on_command(const lcm_recv_buf_t *rbuf, const char *channel, void *user) {
  (void)channel;
  io_lcm_t *s = user;
  pour_command_t msg;
  const int n = pour_command_t_decode(rbuf->data, 0, (int)rbuf->data_size, &msg);
  if (n < 0 || (uint32_t)n != rbuf->data_size) {
    s->in->n_dropped++;
    return;
  }
  s->in->have_command = true;
  pour_commands_t *c = s->in->commands;
  if (c != NULL) { /* one message: its e-stop level first, then what it asks for under that level */
    pour_commands_estop(c, POUR_ESTOP_BUS, msg.estop != 0);
    if (msg.clear_faults != 0) {
      pour_commands_clear(c);
    }
    if (msg.stop != 0) {
      pour_commands_stop(c);
    }
    if (msg.reset != 0) {
      pour_commands_reset(c);
    }
  }
}

static int64_t now_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* select() gives µs resolution where lcm_handle_timeout() has ms; lcm_handle() then reads the
 * datagram that is known to be there. Returns at the first sample so that a lockstep caller sees
 * every sample; a real-time caller polls again with timeout 0 until nothing is left. */
static int io_lcm_wait(pour_io_t *io, int64_t timeout_us, pour_io_input_t *in) {
  io_lcm_t *s = io->ctx;
  const int fd = lcm_get_fileno(s->lcm);
  const int64_t deadline = now_us() + (timeout_us < 0 ? 0 : timeout_us);
  s->in = in;
  s->got_sample = 0;
  int rc = 0;
  for (;;) {
    int64_t wait_us = deadline - now_us();
    if (wait_us < 0) {
      wait_us = 0;
    }
    fd_set fds;
    FD_ZERO(&fds);
    FD_SET(fd, &fds);
    struct timeval tv = {.tv_sec = (time_t)(wait_us / 1000000), .tv_usec = (suseconds_t)(wait_us % 1000000)};
    const int r = select(fd + 1, &fds, NULL, NULL, &tv);
    if (r < 0) {
      rc = errno == EINTR ? 0 : -1; /* a signal ends the wait; the caller checks its stop flag */
      break;
    }
    if (r == 0) {
      break;
    }
    if (lcm_handle(s->lcm) != 0) {
      rc = -1;
      break;
    }
    if (s->got_sample) {
      rc = 1;
      break;
    }
  }
  s->in = NULL;
  return rc;
}

static int io_lcm_send_torque(pour_io_t *io, const pour_io_answer_t *a) {
  io_lcm_t *s = io->ctx;
  pour_torque_t msg;
  memset(&msg, 0, sizeof msg);
  msg.utime = a->utime;
  msg.seq = a->sample_seq;
  msg.state_utime = a->sample_utime;
  msg.episode = a->episode;
  msg.torque_q15 = a->out->torque;
  msg.torque = (double)a->out->torque / 32768.0 * (double)a->tau_max_mnm * 1e-3;
  msg.action = (int8_t)a->out->action;
  msg.mode = (int8_t)a->out->mode;
  msg.faults = (int16_t)a->out->faults;
  msg.weights_hash = (int32_t)a->weights_hash;
  for (int i = 0; i < POUR_OBS_N; i++) {
    msg.obs_q15[i] = a->obs->x[i];
  }
  msg.n_actions = (int8_t)a->n_actions;
  for (int i = 0; i < a->n_actions && i < POUR_POLICY_MAX_ACTIONS; i++) {
    msg.probs_q15[i] = a->out->probs[i];
  }
  return pour_torque_t_publish(s->lcm, POUR_LCM_CHANNEL_TORQUE, &msg) == 0 ? 0 : -1;
}

static int io_lcm_send_status(pour_io_t *io, const pour_io_status_t *st) {
  io_lcm_t *s = io->ctx;
  pour_controller_status_t msg;
  memset(&msg, 0, sizeof msg);
  msg.utime = st->utime;
  msg.tick = st->tick;
  msg.mode = (int8_t)st->mode;
  msg.faults = (int16_t)st->faults;
  msg.limits = (int8_t)st->limits;
  msg.timing = st->lockstep ? 1 : 0;
  msg.overruns = st->overruns;
  msg.late_max_us = st->late_max_us;
  msg.step_time_ns = st->step_time_ns;
  msg.step_time_max_ns = st->step_time_max_ns;
  msg.states_received = st->states_received;
  msg.messages_dropped = st->messages_dropped;
  msg.stale_ticks = st->stale_ticks;
  msg.weights_hash = (int32_t)st->weights_hash;
  return pour_controller_status_t_publish(s->lcm, POUR_LCM_CHANNEL_STATUS, &msg) == 0 ? 0 : -1;
}

static void io_lcm_close(pour_io_t *io) {
  io_lcm_t *s = io->ctx;
  if (s != NULL) {
    lcm_destroy(s->lcm);
    free(s);
  }
  io->ctx = NULL;
}

int pour_io_lcm_open(pour_io_t *io, const char *url) {
  const char *u = url != NULL && url[0] != '\0' ? url : POUR_LCM_DEFAULT_URL;
  io_lcm_t *s = calloc(1, sizeof *s);
  if (s == NULL) {
    fprintf(stderr, "pour_controller: out of memory\n");
    return -1;
  }
  s->lcm = lcm_create(u);
  if (s->lcm == NULL) {
    fprintf(stderr, "pour_controller: cannot open LCM at '%s'\n", u);
    free(s);
    return -1;
  }
  if (lcm_subscribe(s->lcm, POUR_LCM_CHANNEL_SENSORS, on_sensors, s) == NULL ||
      lcm_subscribe(s->lcm, POUR_LCM_CHANNEL_COMMAND, on_command, s) == NULL) {
    fprintf(stderr, "pour_controller: cannot subscribe on '%s'\n", u);
    lcm_destroy(s->lcm);
    free(s);
    return -1;
  }
  io->ctx = s;
  io->wait = io_lcm_wait;
  io->send_torque = io_lcm_send_torque;
  io->send_status = io_lcm_send_status;
  io->close = io_lcm_close;
  return 0;
}
