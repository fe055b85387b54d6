/* SPDX-License-Identifier: MIT */
/* The controller's LCM handlers (firmware/ports/linux/io_lcm.c) on arbitrary messages, through the real
 * LCM library: the input becomes an LCM log of events on POUR_SENSORS, POUR_COMMAND and another channel,
 * which pour_io_lcm_open plays back ("file://" provider) into the port's own subscriptions. Checks: no
 * crash or undefined behaviour (UBSan: negative and huge readings into the port's unsigned count), every
 * event on our channels is either counted as a sample or command or counted as dropped, and the last
 * sample reaches the port reading for reading (the core's estimator, not the port, judges its values).
 * The file provider plays the log on a thread of its own, so this runs at about a thousand executions per
 * second. */
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "io_lcm.h"
#include "pour_command_t.h"
#include "pour_lcm/channels.h"
#include "pour_sensor_sample_t.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      fprintf(stderr, "%s:%d: property broken: %s\n", __FILE__, __LINE__, #cond); \
      abort();                                                        \
    }                                                                 \
  } while (0)

/* Input: events, each one byte of channel (0 state, 1 command, 2 other), two of length, the payload. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static int fd = -1;
  static char path[64], url[128];
  if (fd < 0) {
    fd = memfd_create("fuzz.lcmlog", 0);
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    snprintf(url, sizeof url, "file://%s?speed=0", path);
  }
  CHECK(fd >= 0 && ftruncate(fd, 0) == 0);
  lcm_eventlog_t *log = lcm_eventlog_create(path, "w");
  CHECK(log != NULL);
  static const char *const channels[] = {POUR_LCM_CHANNEL_SENSORS, POUR_LCM_CHANNEL_COMMAND, "POUR_OTHER"};
  uint32_t ours = 0, commands = 0;
  pour_sensor_sample_t last; /* the last event on POUR_SENSORS that decodes exactly */
  int have_last = 0;
  size_t at = 0;
  for (int64_t k = 0; at + 3 <= size && k < 64; ++k) {
    const unsigned ch = data[at] % 3u;
    size_t len = (size_t)data[at + 1] | (size_t)data[at + 2] << 8;
    at += 3;
    if (len > size - at) len = size - at;
    lcm_eventlog_event_t ev;
    memset(&ev, 0, sizeof ev);
    ev.timestamp = 1000 + k;
    ev.channel = (char *)channels[ch];
    ev.channellen = (int32_t)strlen(channels[ch]);
    ev.data = (void *)(data + at);
    ev.datalen = (int32_t)len;
    CHECK(lcm_eventlog_write_event(log, &ev) == 0);
    at += len;
    ours += ch < 2u;
    if (ch == 1u && pour_command_t_decode(ev.data, 0, ev.datalen, &(pour_command_t){0}) == ev.datalen) ++commands;
    pour_sensor_sample_t m;
    if (ch == 0u && pour_sensor_sample_t_decode(ev.data, 0, ev.datalen, &m) == ev.datalen) {
      last = m;
      have_last = 1;
    }
  }
  lcm_eventlog_destroy(log);
  if (at == 0) {
    return 0; /* LCM refuses to play back a log without events */
  }
  pour_io_t io;
  memset(&io, 0, sizeof io);
  CHECK(pour_io_lcm_open(&io, url) == 0);
  pour_io_input_t in;
  memset(&in, 0, sizeof in);
  /* wait returns at each sample; at the end of the log the file provider reports an error (rc < 0). */
  while (io.wait(&io, 2000, &in) > 0) {
  }
  io.close(&io);
  CHECK(in.n_samples + in.n_dropped + commands == ours);
  CHECK(in.have_command == (commands > 0));
  CHECK((in.n_samples > 0) == have_last);
  if (have_last) {
    CHECK(in.sample_seq == last.seq && in.sensors.seq == (uint32_t)((uint64_t)last.seq & 0xFFFFFFFFu));
    CHECK(in.sensors.encoder == (uint32_t)last.encoder && in.sensors.scale_rotating_g == last.scale_rotating_g &&
          in.sensors.scale_target_g == last.scale_target_g);
  }
  return 0;
}
