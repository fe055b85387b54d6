/* SPDX-License-Identifier: MIT */
/* Instructions per current-loop interrupt (pour_drive_isr) and per 1 kHz drive tick on QEMU mps2-an386
 * under -icount shift=0 (one instruction per virtual ns), each call timed on its own by SysTick over inputs
 * that take every branch of the running loop: flux braking on and off, the voltage limit reached and not,
 * the current limit, dead-time compensation on both sides of its band; then the self-calibration's periods.
 * Prints figures; fails on nothing. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "icount.h"
#include "pour/board_facts.h"
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

/* The board's analog chain (pour/board_facts.h): the amplifiers' bias at zero current, the sign of a phase
 * current against its count, and the bus divider. */
#define BIAS POUR_BOARD_OFFSET_NOMINAL_COUNTS
#define SIGN POUR_BOARD_CURRENT_SIGN
/* the ADC count of a bus voltage [mV] */
#define VBUS_COUNTS(mv)                                                                                      \
  ((uint16_t)(((uint64_t)(mv) * 4096u * 1000u + (uint64_t)POUR_BOARD_ADC_VREF_MV * POUR_BOARD_VBUS_DIVIDER_MILLI / 2u) / \
              ((uint64_t)POUR_BOARD_ADC_VREF_MV * POUR_BOARD_VBUS_DIVIDER_MILLI)))
#define VBUS_24V VBUS_COUNTS(24000u)

/* phase currents within ±3 A summing to zero (no trip), the bus between 23.5 and 25.4 V (flux braking
 * from 24.5 V), any encoder position */
static void make_sample(pour_drive_sample_t *s) {
  const int32_t ia = (int32_t)(next() % 201u) - 100, ib = (int32_t)(next() % 201u) - 100;
  s->adc_phase[0] = (uint16_t)(BIAS + SIGN * ia);
  s->adc_phase[1] = (uint16_t)(BIAS + SIGN * ib);
  s->adc_phase[2] = (uint16_t)(BIAS - SIGN * (ia + ib));
  s->adc_vbus = (uint16_t)(VBUS_COUNTS(23500u) + next() % (VBUS_COUNTS(25400u) - VBUS_COUNTS(23500u) + 1u));
  s->encoder = (uint16_t)(next() & 4095u);
}

/* The self-calibration's periods (pour_drive_isr while MEASURING, the last one applying the results), around
 * a plant outside the timed window: the default motor's R and L per axis (exact first-order steps), the legs'
 * dead time, the rotor aligned with the current vector at once (8 pole pairs), the compares a period late. */
static int bench_calibration(uint64_t insn_per_kilotick, uint32_t empty) {
  const pour_drive_config_t config = pour_drive_default_config();
  if (pour_drive_init(&drv, &config) != POUR_OK) return 1;
  const pour_drive_sample_t idle = {{BIAS, BIAS, BIAS}, VBUS_24V, 0};
  pour_drive_output_t out;
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) pour_drive_isr(&drv, &idle, &out);
  if (pour_drive_calibrate(&drv) != POUR_OK) return 1;
  const double r = 0.2865, k = 1.0 - exp(-5e-5 * r / 150.5e-6), vbus = VBUS_24V * (POUR_BOARD_ADC_VREF_MV / 1e3) * (POUR_BOARD_VBUS_DIVIDER_MILLI / 1e3) / 4096.0;
  const double counts_per_amp = SIGN * (POUR_BOARD_SHUNT_UOHM / 1e6) * (POUR_BOARD_AMP_GAIN_MILLI / 1e3) * 4096.0 / (POUR_BOARD_ADC_VREF_MV / 1e3);
  double ia = 0.0, ib = 0.0, angle = 0.0;
  double duty[3] = {0.5, 0.5, 0.5};
  uint32_t worst = 0u, last = 0u;
  uint64_t sum = 0u;
  uint32_t n = 0u;
  while (drv.state == POUR_DRIVE_MEASURING && n < 100000u) {
    const double a = ia, b = -0.5 * ia + 0.8660254 * ib, c = -0.5 * ia - 0.8660254 * ib;
    const int32_t count = (int32_t)floor(angle / 6.283185307 * 4096.0 / 8.0);
    pour_drive_sample_t s = {{(uint16_t)(BIAS + a * counts_per_amp + 0.5), (uint16_t)(BIAS + b * counts_per_amp + 0.5),
                              (uint16_t)(BIAS + c * counts_per_amp + 0.5)},
                             VBUS_24V, (uint16_t)(count & 4095)};
    /* each leg less the dead time's share with the sign of its current (what the modulation compensates) */
    const double i_leg[3] = {a, b, c};
    double v[3];
    for (int j = 0; j < 3; ++j) {
      const double sgn = i_leg[j] > 0.05 ? 1.0 : (i_leg[j] < -0.05 ? -1.0 : i_leg[j] / 0.05);
      v[j] = (duty[j] - sgn * 800e-9 * 20000.0) * vbus;
    }
    const double va = v[0], vb = v[1], vc = v[2];
    const double valpha = (2.0 * va - vb - vc) / 3.0, vbeta = (vb - vc) / 1.7320508;
    ia += k * (valpha / r - ia);
    ib += k * (vbeta / r - ib);
    if (ia * ia + ib * ib > 0.25) {
      double e = atan2(ib, ia);
      while (e < angle - 3.14159265) e += 6.283185307; /* unwrapped: the rotor turns, it does not jump */
      while (e > angle + 3.14159265) e -= 6.283185307;
      angle = e;
    }
    const uint32_t t0 = now();
    pour_drive_isr(&drv, &s, &out);
    const uint32_t t = elapsed(t0, now()) - empty;
    if (drv.state == POUR_DRIVE_MEASURING) worst = t > worst ? t : worst;
    last = t;
    sum += t;
    ++n;
    for (int j = 0; j < 3; ++j) duty[j] = out.pwm_enable ? (double)out.compare[j] / drv.period : 0.5;
  }
  pour_motor_cal_result_t res = {0};
  const pour_motor_cal_status_t st = pour_drive_calibration(&drv, &res);
  printf("self-calibration interrupt (pour_drive_isr while MEASURING): worst %u instructions, average %u; the last "
         "(results applied, the current loop's gains recomputed) %u; %u periods, status %d: R %u uohm, L %u nH, %u pole pairs, "
         "direction %d, offset %u\n",
         (unsigned)(worst * insn_per_kilotick / 1000u), (unsigned)(sum * insn_per_kilotick / 1000u / (n ? n : 1u)),
         (unsigned)(last * insn_per_kilotick / 1000u), (unsigned)n, (int)st, (unsigned)res.r_phase_uohm,
         (unsigned)res.l_phase_nh, (unsigned)res.pole_pairs, (int)res.encoder_direction,
         (unsigned)res.electrical_offset);
  return 0;
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
  const pour_drive_sample_t idle = {{BIAS, BIAS, BIAS}, VBUS_24V, 0};
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
  return bench_calibration(insn_per_kilotick, empty);
}
