/* SPDX-License-Identifier: MIT */
/* The controller process's I/O, behind one narrow interface: one implementation per transport
 * (io_lcm.c: LCM, io_socketcan.c: the CAN node on SocketCAN). The loop in controller.c never sees a
 * transport. */
#ifndef POUR_LINUX_IO_H
#define POUR_LINUX_IO_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/commands.h"
#include "pour/control.h"
#include "pour/sensors.h"

/* What arrived during one wait. Only the latest sensor sample and the latest command are kept. */
typedef struct {
  uint32_t n_samples;     /* sensor samples decoded during this wait (> 1: older ones were superseded) */
  pour_sensors_t sensors; /* the latest sample, as the sensors read it (the core's estimator judges it) */
  int64_t sample_utime;   /* its source time stamp [µs], echoed in the answer */
  int64_t sample_seq;     /* its full sequence number (sensors.seq is the low 32 bits) */
  int32_t episode;        /* its episode index (transports without one report 0) */
  bool have_command;     /* a command arrived */
  pour_commands_t *commands; /* the loop's, or NULL: a transport feeds each command into it as it arrives, so
                              * that the order within a tick keeps its meaning (docs/safety.md) */
  uint32_t n_dropped;    /* messages on our channels that failed to decode */
} pour_io_input_t;

/* The answer to one sensor sample. */
typedef struct {
  int64_t utime;         /* send time [µs], controller wall clock */
  int64_t sample_seq;    /* seq of the answered sample */
  int64_t sample_utime;  /* utime of the answered sample [µs] */
  int32_t episode;       /* episode of the answered sample */
  const pour_control_output_t *out;
  uint8_t n_actions;
  const pour_obs_t *obs; /* observation the policy saw (from the estimated state) */
  int32_t tau_max_mnm;   /* scale of the torque command [mN·m] */
  uint32_t weights_hash; /* content hash of the policy in use */
} pour_io_answer_t;

/* Controller health, published at about 10 Hz. */
typedef struct {
  int64_t utime;           /* [µs], controller wall clock */
  int64_t tick;            /* ticks since start */
  uint8_t mode;            /* pour_mode_t */
  uint16_t faults;         /* POUR_FAULT_* */
  uint8_t limits;          /* POUR_LIMIT_* */
  bool lockstep;           /* one tick per sensor sample instead of a 1 kHz wall clock */
  int64_t overruns;        /* ticks that finished after their deadline */
  int32_t late_max_us;     /* worst tick-start lateness since the last status [µs] */
  int32_t step_time_ns;    /* last pour_control_step [ns] */
  int32_t step_time_max_ns;/* longest step since the last status [ns] */
  int64_t states_received;
  int64_t messages_dropped;
  int64_t stale_ticks;
  uint32_t weights_hash;
} pour_io_status_t;

typedef struct pour_io pour_io_t;
struct pour_io {
  void *ctx;
  /* Waits at most timeout_us (0: poll) for input and accumulates it into *in (which the caller
   * zeroes). Returns 1 if a sensor sample arrived, 0 if not, negative on a transport error. */
  int (*wait)(pour_io_t *io, int64_t timeout_us, pour_io_input_t *in);
  /* Optional (NULL: the loop's own input stands): once per tick, the transport's part of the control
   * input. The CAN node supplies all of it there, its watchdog as the link fault included. */
  void (*begin_tick)(pour_io_t *io, pour_control_input_t *in);
  /* Optional (NULL: none): once per tick before the step, the transport's work on the core itself. The CAN
   * transport answers parameter requests there and puts an accepted write in force (pour/params.h). */
  void (*service)(pour_io_t *io, pour_control_t *ctl);
  /* Sends the answer to a sample; returns 0 or negative on a transport error. */
  int (*send_torque)(pour_io_t *io, const pour_io_answer_t *answer);
  /* Sends the health status; returns 0 or negative on a transport error. */
  int (*send_status)(pour_io_t *io, const pour_io_status_t *status);
  /* Releases the transport. */
  void (*close)(pour_io_t *io);
};

#endif /* POUR_LINUX_IO_H */
