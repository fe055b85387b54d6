/* SPDX-License-Identifier: MIT */
/* The drive's calibration as the board runs it, once a tick after the control step: a CalibrationStart the
 * CAN node accepted (config.can_calibrate) starts the drive's sequence (pour_drive_calibrate: the current-
 * loop interrupt runs it inside pour_drive_isr, which the port calls as always); the e-stop or RUN ends it
 * with the bucket held; a good result is stored through calibration_store, and the outcome goes on the bus
 * unasked: OK, WRITE_FAILED (the flash refused: nothing valid stored, RUN stays refused) or the reason the
 * sequence stopped. */
#ifndef POUR_CALIBRATION_FLOW_H
#define POUR_CALIBRATION_FLOW_H

#include <stdbool.h>
#include <stdint.h>

#include "calibration_store.h"
#include "pour/can_node.h"
#include "pour/drive.h"

typedef struct {
  pour_motor_cal_status_t seen;   /* the drive's calibration status at the last tick */
  pour_cal_status_t stored;       /* the flash block's state: POUR_CAL_OK is the board's calibration_valid
                                     (board_guard), which RUN needs */
  pour_calibration_t calibration; /* the stored calibration, when stored is POUR_CAL_OK */
} pour_calibration_flow_t;

/* What was loaded at boot (pour_calibration_load's status and, when OK, the block). */
void pour_calibration_flow_init(pour_calibration_flow_t *flow, pour_cal_status_t stored, const pour_calibration_t *cal);

/* One tick (mode: the core's pour_mode_t of this tick). Returns true while the sequence runs: the port then
 * keeps the power stage on and lets the drive's own brake request (released) stand. */
bool pour_calibration_flow_tick(pour_calibration_flow_t *flow, pour_can_node_t *node, pour_drive_t *drv, uint8_t mode,
                                const pour_flash_t *flash);

/* The CAN status of a finished sequence's reason (POUR_CAN_CAL_BAD_RESISTANCE .. _ABORTED). */
uint8_t pour_calibration_flow_reason(pour_motor_cal_status_t status);

#endif /* POUR_CALIBRATION_FLOW_H */
