/* SPDX-License-Identifier: MIT */
#include "controller.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "hal_brake.h"
#include "hal_lines.h"
#include "hal_motor.h"
#include "hal_power.h"
#include "port_tick.h"
#include "pour_lcm/channels.h"

#define PERIOD_NS 1000000LL

static int64_t mono_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static int64_t wall_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (int64_t)ts.tv_sec * 1000000LL + ts.tv_nsec / 1000;
}

static void sleep_until_ns(int64_t t_ns) {
  const struct timespec ts = {.tv_sec = (time_t)(t_ns / 1000000000LL), .tv_nsec = (long)(t_ns % 1000000000LL)};
  /* EINTR (a signal) just ends the sleep early: the loop then checks its stop flag. */
  (void)clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
}

pour_linux_config_t pour_linux_default_config(void) {
  pour_linux_config_t c;
  memset(&c, 0, sizeof c);
  c.lockstep = false;
  c.stall_ms = 2000; /* longer than host_sim takes to reset a world between episodes, even on a loaded machine */
  c.control = pour_control_default_config();
  return c;
}

typedef struct {
  const pour_linux_config_t *config;
  pour_io_t *io;
  pour_control_t ctl;
  pour_linux_stats_t *stats;
  pour_commands_t commands; /* the commands since the last tick, in their order (the transport feeds it) */
  bool have_last;         /* an answer was sent (for lockstep resends) */
  int32_t last_episode;
  int64_t last_seq;
  int64_t last_utime;
  pour_control_output_t out;
  /* status period bookkeeping */
  int64_t next_status_ns;
  int64_t period_late_max_us;
  int64_t period_step_max_ns;
  int32_t last_step_ns;
} loop_t;

static void send_answer(loop_t *l) {
  pour_control_probs(&l->ctl, &l->out); /* POUR_TORQUE carries them: the step leaves them to this call */
  const pour_io_answer_t a = {
      .utime = wall_us(),
      .sample_seq = l->last_seq,
      .sample_utime = l->last_utime,
      .episode = l->last_episode,
      .out = &l->out,
      .n_actions = l->config->weights->n_actions,
      .obs = &l->ctl.obs,
      .tau_max_mnm = l->config->weights->tau_max_mnm,
      .weights_hash = l->config->weights->content_hash,
  };
  if (l->io->send_torque(l->io, &a) != 0) {
    l->stats->io_errors++;
  } else {
    l->stats->answers++;
  }
}

static void maybe_send_status(loop_t *l, bool force) {
  const int64_t now = mono_ns();
  if (!force && now < l->next_status_ns) {
    return;
  }
  l->next_status_ns = now + POUR_LCM_STATUS_PERIOD_MS * 1000000LL;
  pour_linux_stats_t *st = l->stats;
  const pour_io_status_t s = {
      .utime = wall_us(),
      .tick = st->ticks,
      .mode = l->out.mode,
      .faults = l->out.faults,
      .limits = l->out.limits,
      .lockstep = l->config->lockstep,
      .overruns = st->overruns,
      .late_max_us = (int32_t)l->period_late_max_us,
      .step_time_ns = l->last_step_ns,
      .step_time_max_ns = (int32_t)l->period_step_max_ns,
      .states_received = st->states_received,
      .messages_dropped = st->messages_dropped,
      .stale_ticks = st->stale_ticks,
      .weights_hash = l->config->weights->content_hash,
  };
  if (l->io->send_status(l->io, &s) != 0) {
    st->io_errors++;
  }
  if (l->config->verbose) {
    fprintf(stderr, "pour_controller: tick %lld mode %u faults 0x%04x states %lld dropped %lld overruns %lld\n",
            (long long)st->ticks, (unsigned)l->out.mode, (unsigned)l->out.faults, (long long)st->states_received,
            (long long)st->messages_dropped, (long long)st->overruns);
  }
  l->period_late_max_us = 0;
  l->period_step_max_ns = 0;
}

/* Folds one wait's counters into the loop (its commands went into l->commands as they arrived). */
static void absorb(loop_t *l, const pour_io_input_t *in) {
  l->stats->states_received += in->n_samples;
  l->stats->messages_dropped += in->n_dropped;
}

static void tick(loop_t *l, const pour_io_input_t *in, bool fresh) {
  pour_control_input_t ci;
  memset(&ci, 0, sizeof ci);
  ci.sensors_fresh = fresh;
  if (fresh) {
    ci.sensors = in->sensors;
  }
  pour_commands_take(&l->commands, &ci);
  if (l->io->service != NULL) {
    l->io->service(l->io, &l->ctl);
  }
  if (l->io->begin_tick != NULL) {
    l->io->begin_tick(l->io, &ci);
  }
  /* No episode logic here: a new run starts only on an explicit reset, which the core refuses in RUN. */
  if (ci.reset) {
    l->stats->resets++;
  }

  const uint16_t faults_before = l->out.faults;
  const int64_t t0 = mono_ns();
  pour_port_tick(&l->ctl, &ci, &l->out);
  const int64_t dt = mono_ns() - t0;
  if ((l->out.faults & ~faults_before) != 0u) {
    fprintf(stderr, "pour_controller: fault 0x%04x latched at tick %lu (docs/safety.md names the bits); "
            "controlled stop, then safe until cleared (POUR_COMMAND clear_faults, e.g. pour-lcm-cmd --clear)\n",
            (unsigned)l->out.faults, (unsigned long)l->out.tick);
  }

  pour_linux_stats_t *st = l->stats;
  st->ticks++;
  l->last_step_ns = (int32_t)dt;
  if (dt > st->step_time_max_ns) {
    st->step_time_max_ns = dt;
  }
  if (dt > l->period_step_max_ns) {
    l->period_step_max_ns = dt;
  }
  if (!fresh) {
    st->stale_ticks++;
  } else {
    l->have_last = true;
    l->last_episode = in->episode;
    l->last_seq = in->sample_seq;
    l->last_utime = in->sample_utime;
    send_answer(l);
  }
}

static bool done(const loop_t *l, volatile sig_atomic_t *stop, int64_t t_end_ns) {
  if (*stop) {
    return true;
  }
  if (l->config->max_states > 0 && l->stats->answers >= l->config->max_states) {
    return true;
  }
  return t_end_ns > 0 && mono_ns() >= t_end_ns;
}

/* Real time: tick k starts at t0 + k ms. All samples that arrived since the last tick are read and
 * the latest is used. A tick that ends after its deadline is an overrun; after a stall of more
 * than one period the schedule restarts from now rather than bursting to catch up. */
static void run_realtime(loop_t *l, volatile sig_atomic_t *stop, int64_t t_end_ns) {
  int64_t next = mono_ns() + PERIOD_NS;
  while (!done(l, stop, t_end_ns)) {
    sleep_until_ns(next);
    const int64_t start = mono_ns();
    const int64_t late_us = (start - next) / 1000;
    if (late_us > 0) {
      l->stats->late_sum_us += late_us;
      if (late_us > l->stats->late_max_us) {
        l->stats->late_max_us = late_us;
      }
      if (late_us > l->period_late_max_us) {
        l->period_late_max_us = late_us;
      }
    }
    pour_io_input_t in;
    memset(&in, 0, sizeof in);
    in.commands = &l->commands;
    int r;
    int n_waits = 0;
    while ((r = l->io->wait(l->io, 0, &in)) > 0 && n_waits < 1000) {
      n_waits++;
    }
    if (r < 0) {
      l->stats->io_errors++;
    }
    absorb(l, &in);
    tick(l, &in, in.n_samples > 0);
    maybe_send_status(l, false);
    const int64_t end = mono_ns();
    if (end > next + PERIOD_NS) {
      l->stats->overruns++;
    }
    next += PERIOD_NS;
    if (end > next + PERIOD_NS) {
      next = end + PERIOD_NS;
    }
  }
}

/* Lockstep: every sensor sample gets exactly one tick and one answer, whatever the wall clock does, so a
 * run is deterministic. A resent sample (same episode and seq) gets the same answer again without a tick.
 * If no sample comes for stall_ms, the loop ticks at 1 kHz on stale input, so that the core's input
 * timeout trips as it would in real time. */
static void run_lockstep(loop_t *l, volatile sig_atomic_t *stop, int64_t t_end_ns) {
  int64_t last_state_ns = mono_ns();
  int64_t next_stale_ns = 0;
  bool stalled = false;
  const int64_t stall_ns = l->config->stall_ms * 1000000LL;
  while (!done(l, stop, t_end_ns)) {
    const int64_t now = mono_ns();
    int64_t until = stalled ? next_stale_ns : last_state_ns + stall_ns;
    if (l->next_status_ns < until) {
      until = l->next_status_ns;
    }
    if (t_end_ns > 0 && t_end_ns < until) {
      until = t_end_ns;
    }
    const int64_t timeout_us = until > now ? (until - now) / 1000 : 0;
    pour_io_input_t in;
    memset(&in, 0, sizeof in);
    in.commands = &l->commands;
    const int r = l->io->wait(l->io, timeout_us, &in);
    if (r < 0) {
      l->stats->io_errors++;
    }
    absorb(l, &in);
    if (in.n_samples > 0) {
      stalled = false;
      last_state_ns = mono_ns();
      if (l->have_last && in.episode == l->last_episode && in.sample_seq == l->last_seq) {
        l->stats->duplicates++;
        send_answer(l);
      } else {
        tick(l, &in, true);
      }
    } else {
      const int64_t t = mono_ns();
      if (!stalled && t - last_state_ns >= stall_ns) {
        stalled = true;
        next_stale_ns = t;
      }
      if (stalled && t >= next_stale_ns) {
        tick(l, &in, false);
        next_stale_ns += PERIOD_NS;
        if (t > next_stale_ns + PERIOD_NS) {
          next_stale_ns = t + PERIOD_NS;
        }
      }
    }
    maybe_send_status(l, false);
  }
}

int pour_linux_run(const pour_linux_config_t *config, pour_io_t *io, volatile sig_atomic_t *stop,
                   pour_linux_stats_t *stats) {
  static loop_t l; /* large (the core's state); one loop per process */
  memset(&l, 0, sizeof l);
  pour_commands_init(&l.commands);
  memset(stats, 0, sizeof *stats);
  l.config = config;
  l.io = io;
  l.stats = stats;
  pour_hal_brake_init();
  pour_hal_power_init();
  pour_hal_motor_init();
  const pour_status_t s = pour_control_init(&l.ctl, &config->control, config->weights);
  if (s != POUR_OK) {
    return (int)s;
  }
  l.out.mode = (uint8_t)l.ctl.mode;
  l.next_status_ns = mono_ns();
  const int64_t t_end_ns = config->duration_ms > 0 ? mono_ns() + config->duration_ms * 1000000LL : 0;
  if (config->lockstep) {
    run_lockstep(&l, stop, t_end_ns);
  } else {
    run_realtime(&l, stop, t_end_ns);
  }
  maybe_send_status(&l, true);
  stats->mode = l.out.mode;
  stats->faults = l.out.faults;
  stats->brake_engagements = pour_hal_brake_engagements();
  stats->power_cuts = pour_hal_power_cuts();
  return 0;
}
