/* SPDX-License-Identifier: MIT */
/* Instructions per current-loop interrupt (pour_drive_isr) and per 1 kHz drive tick on QEMU mps2-an386
 * under -icount shift=0 (one instruction per virtual ns), each call timed on its own by SysTick over inputs
 * that take every branch of the running loop: flux braking on and off, the voltage limit reached and not,
 * the current limit, dead-time compensation on both sides of its band. Prints figures; fails on nothing. */
#include <stdint.h>
#include <stdio.h>

#include "icount.h"
#include "pour/drive.h"

#define N_CALLS 20000u

static uint32_t rng = 0x2545F491u;
static uint32_t next(void) {
  rng ^= rng << 13;
  rng ^= rng >> 17;
  rng ^= rng << 5;
  return rng;
}

static pour_drive_t drv;

/* phase currents within ±3 A summing to zero (no trip), the bus between 23.5 and 25.4 V (flux braking
 * from 24.5 V), any encoder position */
static void make_sample(pour_drive_sample_t *s) {
  const int32_t ia = (int32_t)(next() % 201u) - 100, ib = (int32_t)(next() % 201u) - 100;
  s->adc_phase[0] = (uint16_t)(2048 + ia);
  s->adc_phase[1] = (uint16_t)(2048 + ib);
  s->adc_phase[2] = (uint16_t)(2048 - ia - ib);
  s->adc_vbus = (uint16_t)(1522u + next() % 123u);
  s->encoder = (uint16_t)(next() & 4095u);
}

int main(void) {
  const uint64_t insn_per_kilotick = icount_start();
  uint32_t t0;

  pour_drive_config_t config = pour_drive_default_config();
  config.phase_loss_ms = 1000; /* the synthetic currents do not follow the loop: keep it running */
  if (pour_drive_init(&drv, &config) != POUR_OK) {
    printf("pour_drive_init failed\n");
    return 1;
  }
  pour_drive_sample_t s;
  pour_drive_output_t out;
  const pour_drive_sample_t idle = {{2048, 2048, 2048}, 1554, 0};
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) pour_drive_isr(&drv, &idle, &out);

  uint32_t empty = 0u;
  for (uint32_t i = 0; i < 64u; ++i) {
    t0 = now();
    __asm volatile("" ::: "memory");
    empty += elapsed(t0, now());
  }
  empty /= 64u;
  uint32_t worst = 0u, worst_tick = 0u;
  uint64_t sum = 0u, sum_tick = 0u;
  uint32_t n_isr = 0u, n_tick = 0u, limited = 0u;
  for (uint32_t i = 0; i < N_CALLS && drv.state == POUR_DRIVE_RUN; ++i) {
    if (i % 20u == 0u) {
      /* torques to ±45 N·m (past the current limit), the output turning either way */
      const int32_t torque = (int32_t)(next() % 90001u) - 45000;
      const int32_t motion = (int32_t)(next() % 5u) - 2;
      t0 = now();
      pour_drive_tick(&drv, torque, motion);
      const uint32_t t = elapsed(t0, now()) - empty;
      worst_tick = t > worst_tick ? t : worst_tick;
      sum_tick += t;
      ++n_tick;
    }
    make_sample(&s);
    t0 = now();
    pour_drive_isr(&drv, &s, &out);
    const uint32_t t = elapsed(t0, now()) - empty;
    worst = t > worst ? t : worst;
    sum += t;
    ++n_isr;
    if (out.limits & POUR_DRIVE_LIMIT_VOLTAGE) ++limited;
  }
  printf("calibration: %u.%03u instructions/tick\n", (unsigned)(insn_per_kilotick / 1000u),
         (unsigned)(insn_per_kilotick % 1000u));
  printf("current-loop interrupt (pour_drive_isr): worst %u instructions, average %u (%u calls, %u at the voltage "
         "limit, faults 0x%04x)\n",
         (unsigned)(worst * insn_per_kilotick / 1000u), (unsigned)(sum * insn_per_kilotick / 1000u / n_isr),
         (unsigned)n_isr, (unsigned)limited, (unsigned)drv.faults);
  printf("drive tick (pour_drive_tick): worst %u instructions, average %u\n",
         (unsigned)(worst_tick * insn_per_kilotick / 1000u),
         (unsigned)(sum_tick * insn_per_kilotick / 1000u / (n_tick ? n_tick : 1u)));
  printf("sizeof(pour_drive_t) = %u B\n", (unsigned)sizeof(pour_drive_t));
  return 0;
}
