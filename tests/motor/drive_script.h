/* SPDX-License-Identifier: MIT */
/* A scripted run of the drive for the golden vectors (gen_motor_golden.c writes them on the host,
 * test_drive_golden.c replays them on the host and the emulated Cortex-M4): the default drive calibrated,
 * then POUR_DRIVE_SCRIPT_PERIODS periods of seeded samples (currents within ±3 A summing to zero, the bus
 * between 23.5 and 25.4 V so that flux braking comes and goes, the encoder anywhere) with a new torque
 * every 20 periods (to ±45 N·m, past the current limit) and the output turning either way. */
#ifndef POUR_DRIVE_SCRIPT_H
#define POUR_DRIVE_SCRIPT_H

#include <stdint.h>

#include "pour/board_facts.h"
#include "pour/drive.h"

#define POUR_DRIVE_SCRIPT_PERIODS 1000u

typedef struct {
  uint16_t compare[3];
  int16_t id, iq;
  uint16_t limits, faults;
} pour_drive_golden_t;

static inline uint32_t pour_drive_script_rng(uint32_t *state) {
  *state ^= *state << 13;
  *state ^= *state >> 17;
  *state ^= *state << 5;
  return *state;
}

/* Runs the script; row k of out gets period k's output. Returns 0, or −1 if the drive does not start. */
static inline int pour_drive_script_run(pour_drive_golden_t out[POUR_DRIVE_SCRIPT_PERIODS]) {
  static pour_drive_t drv;
  pour_drive_config_t config = pour_drive_default_config();
  config.phase_loss_ms = 1000; /* the synthetic currents do not follow the loop */
  if (pour_drive_init(&drv, &config) != POUR_OK) return -1;
  uint32_t rng = 20261201u;
  pour_drive_output_t o;
  for (int n = 0; n < POUR_CURRENT_SENSE_CAL_SAMPLES; ++n) {
    const uint16_t noise = (uint16_t)(pour_drive_script_rng(&rng) % 5u);
    const pour_drive_sample_t s = {{(uint16_t)(2551u + noise), 2554u, (uint16_t)(2555u - noise)}, 2867u, 0u}; /* the board's bias; 24 V */
    pour_drive_isr(&drv, &s, &o);
  }
  if (drv.state != POUR_DRIVE_RUN) return -1;
  for (uint32_t k = 0; k < POUR_DRIVE_SCRIPT_PERIODS; ++k) {
    if (k % 20u == 0u) {
      const int32_t torque = (int32_t)(pour_drive_script_rng(&rng) % 90001u) - 45000;
      pour_drive_tick(&drv, torque, (int32_t)(pour_drive_script_rng(&rng) % 5u) - 2);
    }
    const int32_t ia = (int32_t)(pour_drive_script_rng(&rng) % 201u) - 100;
    const int32_t ib = (int32_t)(pour_drive_script_rng(&rng) % 201u) - 100;
    pour_drive_sample_t s;
    s.adc_phase[0] = (uint16_t)(POUR_BOARD_OFFSET_NOMINAL_COUNTS + ia); /* around the board's bias */
    s.adc_phase[1] = (uint16_t)(POUR_BOARD_OFFSET_NOMINAL_COUNTS + ib);
    s.adc_phase[2] = (uint16_t)(POUR_BOARD_OFFSET_NOMINAL_COUNTS - ia - ib);
    s.adc_vbus = (uint16_t)(2808u + pour_drive_script_rng(&rng) % 227u); /* 23.4 .. 25.3 V through 10.389 */
    s.encoder = (uint16_t)(pour_drive_script_rng(&rng) & 4095u);
    pour_drive_isr(&drv, &s, &o);
    for (int p = 0; p < 3; ++p) out[k].compare[p] = o.compare[p];
    out[k].id = o.id;
    out[k].iq = o.iq;
    out[k].limits = o.limits;
    out[k].faults = o.faults;
  }
  return 0;
}

#endif /* POUR_DRIVE_SCRIPT_H */
