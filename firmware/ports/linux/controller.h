/* SPDX-License-Identifier: MIT */
/* The controller process's loop: the firmware core at 1 kHz (or one tick per sensor sample in lockstep),
 * fed through a pour_io_t. No transport and no argument parsing here. */
#ifndef POUR_LINUX_CONTROLLER_H
#define POUR_LINUX_CONTROLLER_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "io.h"
#include "pour/control.h"

typedef struct {
  bool lockstep;          /* one tick per received sensor sample (deterministic) instead of a 1 kHz clock */
  int64_t stall_ms;       /* lockstep: no sample for this long [ms] → tick at 1 kHz on stale input */
  int64_t duration_ms;    /* stop after this long [ms]; 0 runs until a signal */
  int64_t max_states;     /* stop after answering this many sensor samples; 0: no limit */
  pour_control_config_t control;
  const pour_policy_weights_t *weights;
  bool verbose;           /* one line per status period on stderr */
} pour_linux_config_t;

/* What the loop counted; printed at exit and published (in part) on the status channel. */
typedef struct {
  int64_t ticks;
  int64_t states_received;  /* decoded states (in real time some are superseded before a tick) */
  int64_t answers;          /* torque answers sent */
  int64_t duplicates;       /* lockstep: states seen again (resends), answered without a tick */
  int64_t messages_dropped; /* undecodable messages on our channels */
  int64_t stale_ticks;      /* ticks without a fresh state */
  int64_t overruns;         /* real time: ticks that finished after their deadline */
  int64_t late_max_us;      /* real time: worst tick-start lateness [µs] */
  int64_t late_sum_us;      /* real time: sum of tick-start lateness [µs] (mean = sum / ticks) */
  int64_t step_time_max_ns; /* longest pour_control_step [ns] */
  int64_t io_errors;        /* failed sends or waits */
  int64_t resets;           /* reset commands received (the core refuses those that come in RUN) */
  int64_t brake_engagements; /* the brake line engaged after a release (hal_brake) */
  int64_t power_cuts;       /* the power line cut after being on (hal_power) */
  uint8_t mode;             /* pour_mode_t at exit */
  uint16_t faults;          /* fault bits at exit */
} pour_linux_stats_t;

/* Defaults: real time, stall 2000 ms, run until a signal, control defaults of the core. */
pour_linux_config_t pour_linux_default_config(void);

/* Runs until *stop becomes non-zero, the duration or the state count is reached.
 * Returns 0, or a negative pour_status_t if the core refused the configuration. */
int pour_linux_run(const pour_linux_config_t *config, pour_io_t *io, volatile sig_atomic_t *stop,
                   pour_linux_stats_t *stats);

#endif /* POUR_LINUX_CONTROLLER_H */
