/* SPDX-License-Identifier: MIT */
/* The core's vocabulary of health: its modes and its latched fault bits, with one table of their names (the
 * bus, the tools and the logs all print these). Pure: no I/O. */
#ifndef POUR_FAULTS_H
#define POUR_FAULTS_H

#include <stddef.h>
#include <stdint.h>

typedef enum {
  POUR_MODE_IDLE = 0,  /* no state yet (or faults just cleared): safe torque */
  POUR_MODE_RUN = 1,   /* the decision in command, inside the envelope */
  POUR_MODE_FAULT = 2, /* a latched fault: the controlled stop, then brake and power cut until clear_faults */
  POUR_MODE_ESTOP = 3  /* e-stop asserted: zero torque, brake, power cut while it lasts, then FAULT */
} pour_mode_t;
#define POUR_MODE_COUNT 4u

/* Latched fault bits (pour_control_output_t.faults); only clear_faults resets them. */
#define POUR_FAULT_STALE_INPUT 0x0001u /* no fresh sample for longer than input_timeout_ms */
#define POUR_FAULT_ESTOP 0x0002u       /* e-stop was asserted */
#define POUR_FAULT_BAD_INPUT 0x0004u   /* a sensor sample (or the state from it) outside its physical range */
#define POUR_FAULT_POSITION 0x0008u    /* supervisor: θ outside [θmin - margin, θmax + margin] */
#define POUR_FAULT_OVERSPEED 0x0010u   /* supervisor: |θ̇| above the overspeed limit */
#define POUR_FAULT_TORQUE_SIGN 0x0020u /* supervisor: the axis accelerates against the commanded torque */
#define POUR_FAULT_ENCODER 0x0040u     /* supervisor: the encoder does not move under sustained torque */
#define POUR_FAULT_VOLUME 0x0080u      /* supervisor: a scale reading jumped faster than liquid can flow */
#define POUR_FAULT_LINK 0x0100u        /* the transport's command watchdog tripped (the CAN node's) */
#define POUR_FAULT_SEQ 0x0200u         /* supervisor: samples keep arriving but their seq does not advance */
#define POUR_FAULT_SCALE 0x0400u       /* supervisor: the axis accelerates more than the command can (scale) */
#define POUR_FAULT_DRIVE 0x0800u       /* the drive latched a fault of its own (which: DriveTelemetry's word) */
#define POUR_FAULT_ALL 0x0FFFu
#define POUR_FAULT_COUNT 12u           /* bits 0 .. POUR_FAULT_COUNT - 1 */
/* Faults the controlled stop answers actively (the sensors and the motor are still trusted): decelerate,
 * return toward upright at a bounded speed, then brake. Every other fault brakes at once; POUR_FAULT_DRIVE
 * is answered actively too while the drive says it still follows a torque (pour_control_input_t). */
#define POUR_FAULT_ACTIVE_STOP (POUR_FAULT_POSITION | POUR_FAULT_OVERSPEED | POUR_FAULT_VOLUME)

/* The name of one fault bit (a single POUR_FAULT_* value: "STALE_INPUT", ...), NULL for anything else. */
const char *pour_fault_name(uint16_t bit);

/* A fault word as its names joined by ',' ("none" for 0; bits without a name as "BIT<n>"), written into
 * buf of size bytes and always terminated (cut short if it does not fit: POUR_FAULTS_TEXT_MAX holds all 16 bits). */
const char *pour_faults_format(uint16_t faults, char *buf, size_t size);
#define POUR_FAULTS_TEXT_MAX 128u

/* The name of a mode ("IDLE", "RUN", "FAULT", "ESTOP"), NULL outside pour_mode_t. */
const char *pour_mode_name(uint8_t mode);

#endif /* POUR_FAULTS_H */
