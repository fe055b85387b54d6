/* SPDX-License-Identifier: MIT */
/* Latched faults of the drive (the current loop, the power stage, the board's sensors), one word beside the
 * core's POUR_FAULT_* bits. Any of them makes the core fault too (the drive is no longer trusted to follow a
 * torque); which one is named here. */
#ifndef POUR_DRIVE_FAULTS_H
#define POUR_DRIVE_FAULTS_H

#define POUR_DRIVE_FAULT_OVERCURRENT 0x0001u      /* a phase current above the software limit */
#define POUR_DRIVE_FAULT_HW_OVERCURRENT 0x0002u   /* the comparators cut the PWM through TIM1's break input */
#define POUR_DRIVE_FAULT_OVERVOLTAGE 0x0004u      /* bus voltage above its fault threshold */
#define POUR_DRIVE_FAULT_UNDERVOLTAGE 0x0008u     /* bus voltage below its fault threshold */
#define POUR_DRIVE_FAULT_OVERTEMP 0x0010u         /* power stage above its fault temperature */
#define POUR_DRIVE_FAULT_CURRENT_OFFSET 0x0020u   /* a current-sense offset out of range at start-up */
#define POUR_DRIVE_FAULT_PHASE 0x0040u            /* a motor phase open or shorted */
#define POUR_DRIVE_FAULT_ENCODER_DIRECTION 0x0080u /* the motor encoder counts against the commanded motion */
#define POUR_DRIVE_FAULT_ENCODER_MISMATCH 0x0100u /* motor and output encoders disagree beyond the backlash */
#define POUR_DRIVE_FAULT_CALIBRATION 0x0200u      /* no valid calibration (missing, bad CRC, old version) */
#define POUR_DRIVE_FAULT_I2T 0x0400u              /* the motor's thermal (I²t) budget is spent */
#define POUR_DRIVE_FAULT_ALL 0x07FFu
#define POUR_DRIVE_FAULT_COUNT 11u /* bits 0 .. POUR_DRIVE_FAULT_COUNT - 1 of POUR_DRIVE_FAULT_ALL */

/* What ClearErrors may clear (pour_drive_clear_faults): a fault whose cause the drive or the board judges
 * afresh once cleared. OVERCURRENT and PHASE: the loop checks every period again. HW_OVERCURRENT: the board
 * re-arms the break, which fires again while a comparator still trips. OVERVOLTAGE, UNDERVOLTAGE: only with
 * the last bus sample in range. OVERTEMP: the board's protection reads the NTC again. I2T: only once the
 * motor has cooled to half its budget. CURRENT_OFFSET (a broken amplifier, or a cut that would not arm on
 * the offsets): the offsets are measured again with the gates off and the brake engaged, and it clears only
 * if they are in range (the board then re-arms the cut on them).
 * Kept until a self-calibration succeeds (POUR_DRIVE_FAULT_CLEARED_BY_CALIBRATION; a CalibrationStart may
 * start from them): CALIBRATION, ENCODER_DIRECTION (wiring or a wrong calibration: the motor would run
 * away), ENCODER_MISMATCH (a slipped coupling would look fine once re-anchored: the sequence measures the
 * motor's encoder against its own commutation again). */
#define POUR_DRIVE_FAULT_CLEARABLE                                                                            \
  (POUR_DRIVE_FAULT_OVERCURRENT | POUR_DRIVE_FAULT_HW_OVERCURRENT | POUR_DRIVE_FAULT_OVERVOLTAGE |            \
   POUR_DRIVE_FAULT_UNDERVOLTAGE | POUR_DRIVE_FAULT_OVERTEMP | POUR_DRIVE_FAULT_PHASE | POUR_DRIVE_FAULT_I2T |  \
   POUR_DRIVE_FAULT_CURRENT_OFFSET)

#define POUR_DRIVE_FAULT_CLEARED_BY_CALIBRATION                                                               \
  (POUR_DRIVE_FAULT_CALIBRATION | POUR_DRIVE_FAULT_ENCODER_DIRECTION | POUR_DRIVE_FAULT_ENCODER_MISMATCH)

#include <stdint.h>

/* The name of one POUR_DRIVE_FAULT_* bit ("OVERCURRENT", ...), NULL for anything else. */
const char *pour_drive_fault_name(uint32_t bit);

#endif /* POUR_DRIVE_FAULTS_H */
