/* SPDX-License-Identifier: MIT */
/* hal_calibration: the drive's calibration, checked at boot (the board: the block in flash,
 * calibration_store.c). Without a valid one the controller refuses RUN and its Identity frame says why. */
#ifndef POUR_HAL_CALIBRATION_H
#define POUR_HAL_CALIBRATION_H

#include "pour/can_codec.h"
#include "pour/fixed.h"

/* Loads and checks the stored calibration: POUR_OK, or POUR_ECALIBRATION (the reason in detail:
 * pour_hal_calibration_reason). */
pour_status_t pour_hal_calibration_load(void);

/* What a CalibrationStart is answered with (the stored calibration as loaded, and whether this board can
 * measure one: POUR_CAN_CAL_UNAVAILABLE while the drive's calibration routine is not in the firmware). */
void pour_hal_calibration_result(pour_can_calibration_result_t *result);

/* Why the last load failed, a pour_cal_status_t (0: it did not). */
int pour_hal_calibration_reason(void);

#endif /* POUR_HAL_CALIBRATION_H */
