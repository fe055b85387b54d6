/* SPDX-License-Identifier: MIT */
/* A motor behind hal_drive whose phase currents follow the drive's references exactly (an ideal current
 * loop), for the benches that run board_drive without a motor: the QEMU smoke image and the host's fault
 * tests. Fixed point (the smoke image has no float), through the drive's own transforms and gains. */
#ifndef POUR_IDEAL_DRIVE_H
#define POUR_IDEAL_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/drive.h"

/* The three shunt amplifiers' ADC counts of the currents id, iq (per-unit Q15) at the electrical angle of
 * encoder count `encoder`, around the bias `bias` [counts], through drv's gain with the board's sign
 * (pour/board_facts.h: the count falls as current flows into the motor). */
void pour_ideal_phase_counts(const pour_drive_t *drv, q15_t id, q15_t iq, uint16_t encoder, uint16_t bias,
                             uint16_t counts[3]);

/* The torque at the output of q current iq (per-unit Q15) through the motor's constant, the gear ratio and
 * the gearbox's efficiency η [mN·m]: × η motoring (the torque drives the output's motion), ÷ η braking (the
 * load drives the motor), as pour_drive_tick assumes. */
int32_t pour_ideal_torque_mnm(const pour_drive_config_t *c, q15_t iq, bool motoring);

/* ADC counts of a pin voltage [mV] on c's 12-bit converter. */
uint16_t pour_ideal_adc_counts(const pour_drive_config_t *c, uint32_t pin_mv);

#endif /* POUR_IDEAL_DRIVE_H */
