/* SPDX-License-Identifier: MIT */
/* Instructions per control step on QEMU mps2-an386 under -icount shift=0 (one instruction per virtual
 * ns). SysTick runs from the core clock; a calibration loop of known length converts its ticks to
 * instructions. Prints figures; never fails on them. */
#include <stdint.h>
#include <stdio.h>

#include "icount.h"
#include "pour/control.h"
#include "pour/weights_compiled.h"

#define N_STEPS 2000u

static pour_control_t ctl;
static pour_control_input_t inputs[64];

/* A bucket swinging at ±1.9 rad/s, its scales moving, the seq counting: every step a full RUN step (the
 * estimator, the governor's band and every supervisor check compute on every tick). */
static void make_inputs(void) {
  for (unsigned i = 0; i < 64u; ++i) {
    const int32_t k = (int32_t)(i < 32u ? i : 64u - i); /* up and back down, no jump at the ring's seam */
    inputs[i].sensors_fresh = true;
    inputs[i].estop = false;
    inputs[i].clear_faults = false;
    inputs[i].sensors.seq = i;
    inputs[i].sensors.encoder = (uint32_t)(20000 + 40 * k); /* 17-bit counts: ±1.92 rad/s */
    inputs[i].sensors.scale_rotating_g = 10000 - 120 * k;
    inputs[i].sensors.scale_target_g = 110 * k;
  }
}

/* The default configuration with the supervisor running every check on every tick (all armed, windows
 * full) against bounds these synthetic states never cross, so that every step is a RUN step: the worst
 * case, not a cheap FAULT one. */
static pour_control_config_t bench_config(void) {
  pour_control_config_t config = pour_control_default_config();
  config.supervisor.theta_margin_urad = INT32_MAX / 2;
  config.supervisor.omega_against_urad_s = INT32_MAX;
  config.supervisor.encoder_move_urad = 1;
  config.supervisor.volume_step_max = POUR_Q15_MAX;
  config.supervisor.accel_passive_urad_s2 = INT32_MAX;
  config.supervisor.omega_max_urad_s = 50000000;
  config.sensors.jump_max_urad = 1000000; /* the swing turns round within a tick */
  return config;
}

/* Average SysTick ticks (x1000) per step for N_STEPS steps, minus the loop's own cost. */
static uint32_t time_steps(const pour_policy_weights_t *w, int do_step) {
  const pour_control_config_t config = bench_config();
  if (pour_control_init(&ctl, &config, w) != POUR_OK) {
    return 0u;
  }
  pour_control_output_t out;
  const uint32_t t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    inputs[i & 63u].sensors.seq = i + 1u; /* a sender that counts, as the supervisor requires */
    if (do_step) {
      pour_control_step(&ctl, &inputs[i & 63u], &out);
    } else {
      __asm volatile("" : : "r"(&inputs[i & 63u]) : "memory");
    }
  }
  return elapsed(t0, now());
}

/* The schedule as shipped, tick by tick: each step timed on its own, the times summed per phase of the
 * decision period (phase 0: the decision tick, 1: the tick after it, ...), the timer's own cost taken off.
 * Returns the largest per-phase mean [instructions] and prints every phase. */
static uint32_t worst_phase(const pour_policy_weights_t *w, uint32_t insn_per_kilotick, int32_t knee_urad) {
  pour_control_config_t config = bench_config();
  config.safety.knee_theta_urad = knee_urad; /* 0: no fill schedule (the default) */
  if (pour_control_init(&ctl, &config, w) != POUR_OK || w->decision_period_ms > 16u) {
    return 0u;
  }
  uint64_t sum[16] = {0};
  uint32_t empty = 0u;
  for (uint32_t i = 0; i < 64u; ++i) { /* the cost of the timing itself */
    const uint32_t t0 = now();
    __asm volatile("" ::: "memory");
    empty += elapsed(t0, now());
  }
  pour_control_output_t out;
  const uint32_t period = w->decision_period_ms;
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    inputs[i & 63u].sensors.seq = i + 1u;
    const uint32_t t0 = now();
    pour_control_step(&ctl, &inputs[i & 63u], &out);
    sum[i % period] += elapsed(t0, now());
  }
  uint32_t worst = 0u;
  printf("  per tick of the %u ms schedule (phase 0 decides):", (unsigned)period);
  for (uint32_t p = 0; p < period; ++p) {
    const uint64_t n = N_STEPS / period;
    const uint64_t ticks_x1000 = (sum[p] * 1000u) / n - (uint64_t)empty * 1000u / 64u;
    const uint32_t insn = (uint32_t)((ticks_x1000 * insn_per_kilotick) / 1000000u);
    printf(" %u", (unsigned)insn);
    worst = insn > worst ? insn : worst;
  }
  printf("\n");
  return worst;
}

static void report(const char *name, const pour_policy_weights_t *w, uint32_t insn_per_kilotick) {
  const uint32_t loop = time_steps(w, 0);
  const uint32_t run = time_steps(w, 1);
  const uint32_t per_step = (uint32_t)(((uint64_t)(run - loop) * insn_per_kilotick) / (1000u * N_STEPS));
  printf("%-34s %5u instructions/step (n_actions %u, decision every %u ms)\n", name, (unsigned)per_step,
          (unsigned)w->n_actions, (unsigned)w->decision_period_ms);
}

/* Instructions per call of the two kernels a decision tick adds to a hold tick. */
static void report_kernels(const pour_policy_weights_t *w, uint32_t insn_per_kilotick) {
  pour_policy_t policy;
  pour_policy_eval_t ev;
  pour_obs_t obs[64];
  pour_state_t states[64];
  static pour_estimator_t est;
  const pour_sensors_config_t sc = bench_config().sensors;
  if (pour_policy_init(&policy, w, POUR_POLICY_GREEDY, 1u) != POUR_OK || pour_estimator_init(&est, &sc) != POUR_OK) {
    return;
  }
  uint32_t t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    inputs[i & 63u].sensors.seq = i + 1u;
    (void)pour_estimator_update(&est, &inputs[i & 63u].sensors, &states[i & 63u]);
  }
  const uint32_t estimate = elapsed(t0, now());
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    pour_obs_quantize(&w->norm, &states[i & 63u], &obs[i & 63u]);
  }
  const uint32_t quant = elapsed(t0, now());
  static pour_safety_t safety;
  const pour_safety_config_t sfc = bench_config().safety;
  (void)pour_safety_init(&safety, &sfc);
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    (void)pour_safety_apply(&safety, (q15_t)(i * 997u), states[i & 63u].theta_urad, states[i & 63u].omega_urad_s);
  }
  const uint32_t envelope = elapsed(t0, now());
  static pour_supervisor_t sup;
  const pour_supervisor_config_t svc = bench_config().supervisor;
  (void)pour_supervisor_init(&sup, &svc, w->norm.theta_min_urad, w->norm.theta_max_urad);
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    (void)pour_supervisor_step(&sup, &states[i & 63u], true);
    pour_supervisor_record(&sup, &states[i & 63u], (q15_t)(i * 997u));
  }
  const uint32_t supervise = elapsed(t0, now());
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    pour_policy_eval(&policy, &obs[i & 63u], &ev);
  }
  const uint32_t eval = elapsed(t0, now());
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    (void)pour_policy_decide(&policy, &obs[i & 63u], &ev);
  }
  const uint32_t decide = elapsed(t0, now());
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    ev.logits[i & 15u] = (int32_t)i;
    ev.action = (uint8_t)pour_policy_argmax(ev.logits, w->n_actions);
  }
  const uint32_t argmax = elapsed(t0, now());
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    pour_policy_logits(w, &obs[i & 63u], ev.logits);
  }
  const uint32_t logits = elapsed(t0, now());
  t0 = now();
  for (uint32_t i = 0; i < N_STEPS; ++i) {
    ev.logits[0] = (int32_t)i;
    pour_policy_softmax_q15(ev.logits, w->n_actions, ev.probs);
  }
  const uint32_t softmax = elapsed(t0, now());
  const uint64_t scale = 1000ull * N_STEPS;
  printf("  per call (loop included): pour_estimator_update %u, pour_safety_apply %u, pour_supervisor_step + _record %u, "
         "pour_obs_quantize %u, "
         "pour_policy_eval %u = logits %u (the general kernel) + softmax %u + argmax %u;\n"
         "  the greedy decision (pour_policy_decide: the int32 kernel and the argmax, no softmax) %u\n",
         (unsigned)((estimate * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((envelope * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((supervise * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((quant * (uint64_t)insn_per_kilotick) / scale), (unsigned)((eval * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((logits * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((softmax * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((argmax * (uint64_t)insn_per_kilotick) / scale),
         (unsigned)((decide * (uint64_t)insn_per_kilotick) / scale));
}

int main(void) {
  const uint32_t insn_per_kilotick = icount_start();
  make_inputs();
  printf("calibration: %u.%03u instructions/tick\n", (unsigned)(insn_per_kilotick / 1000u),
         (unsigned)(insn_per_kilotick % 1000u));

  /* The compiled policy as shipped, then the worst case: a decision on every tick. */
  pour_policy_weights_t every_tick = pour_weights_compiled;
  every_tick.decision_period_ms = 1u;
  every_tick.content_hash = pour_policy_weights_hash(&every_tick);
  report("control step, average:", &pour_weights_compiled, insn_per_kilotick);
  report("control step, decision every tick:", &every_tick, insn_per_kilotick);
  const uint32_t worst = worst_phase(&pour_weights_compiled, insn_per_kilotick, 0);
  printf("%-34s %5u instructions/step (the shipped schedule's costliest tick)\n", "control step, worst tick:",
         (unsigned)worst);
  /* A rig file's fill schedule puts a knee in the envelope: below it, within the braking curve's last stretch,
   * the speed limit is a square root (safety.c's isqrt64). The swing here (0.92 .. 1.00 rad) runs through it. */
  const uint32_t knee = worst_phase(&pour_weights_compiled, insn_per_kilotick, 1060000);
  printf("%-34s %5u instructions/step (a fill schedule's knee at 1.06 rad, the swing just below it)\n",
         "control step, worst tick, knee:", (unsigned)knee);
  report_kernels(&pour_weights_compiled, insn_per_kilotick);
  printf("controller state: sizeof(pour_control_t) = %u B (the core has no static data)\n",
         (unsigned)sizeof(pour_control_t));
  return 0;
}
