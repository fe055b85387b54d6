/* SPDX-License-Identifier: MIT */
/* The drive on the board, around the motor library (pour/drive.h):
 *   - the current loop's interrupt, once per PWM period: the period's sample (hal_drive) into pour_drive_isr,
 *     its compares and gates back to the timer, the phases shorted while the drive is faulted;
 *   - the 1 kHz tick around the core's step: the board's protection (board_guard) on the loop's latest
 *     sample; the drive's fault word and whether it still follows a torque into the core's input
 *     (drive_faults, drive_trusted); the core's step; the brake engaged at once on a drive fault, with the
 *     power stage kept on until the brake holds (an active stop or the shorted phases need it); the outputs
 *     (port_tick); the torque the core commands, derated, handed to the loop (pour_drive_tick: torque -> q
 *     current through the motor's constants, the conversion host_sim's drive = 1 runs too).
 * One drive per board: the state is this module's. Port-neutral over hal_drive, hal_brake, hal_motor and
 * hal_power, so the board (board_stm32g431.c), the QEMU smoke bench and the host's fault tests run it alike. */
#ifndef POUR_BOARD_DRIVE_H
#define POUR_BOARD_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/can_codec.h"
#include "pour/control.h"
#include "pour/drive.h"

/* The drive with its configuration, the board's protection with its defaults; tau_max_mnm: the torque of the
 * core's Q15 1.0 [mN·m], > 0; calibration_valid: a valid calibration block was loaded (else the drive is
 * faulted with POUR_DRIVE_FAULT_CALIBRATION the period its current offsets are measured, and the brake
 * never releases outside a self-calibration). Starts the current-offset calibration (the gates off). POUR_EINVAL for a bad configuration. */
pour_status_t pour_board_drive_init(const pour_drive_config_t *config, int32_t tau_max_mnm, bool calibration_valid);

/* The drive's self-calibration as the board runs it (the port's calibration flow), called by the tick after the
 * core's step with the drive (masked from the interrupt) and the core's mode; returns true while the sequence
 * runs: the power stage then stays on and the drive's own brake request stands. NULL: none. */
typedef bool (*pour_board_calibration_fn)(pour_drive_t *drv, uint8_t mode);
void pour_board_drive_set_calibration(pour_board_calibration_fn flow);

/* A calibration measured in this power cycle is stored now: the protection starts afresh, as at boot (its
 * latched encoder faults gone, the output anchored again), and a ClearErrors lets the core run. */
void pour_board_drive_calibrated(void);

/* One PWM period (the ADC's end-of-sequence interrupt); nothing if the period's sample is not complete. */
void pour_board_drive_isr(void);

/* One 1 kHz tick: *in (as the bus filled it) gets the drive's faults, then the core steps and its outputs
 * are written (see above). */
void pour_board_drive_tick(pour_control_t *ctl, pour_control_input_t *in, pour_control_output_t *out);

/* The drive's latched fault word (POUR_DRIVE_FAULT_*: the loop's and the protection's). */
uint16_t pour_board_drive_faults(void);

/* The drive as the loop left it: its state (configuration, faults) and its latest period's output. */
const pour_drive_t *pour_board_drive_state(void);
const pour_drive_output_t *pour_board_drive_output(void);

/* What DriveTelemetry carries: the latest period's d and q currents, the bus voltage, the fault word. */
void pour_board_drive_telemetry(pour_can_drive_telemetry_t *t);

#endif /* POUR_BOARD_DRIVE_H */
