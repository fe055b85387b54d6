/* SPDX-License-Identifier: MIT */
/* hal_calibration: the drive's calibration, checked at boot (the board: the block in flash,
 * calibration_store.c). Without a valid one the controller refuses RUN and its Identity frame says why. */
#ifndef POUR_HAL_CALIBRATION_H
#define POUR_HAL_CALIBRATION_H

#include "pour/fixed.h"

/* Loads and checks the stored calibration: POUR_OK, or POUR_ECALIBRATION (the reason in detail:
 * pour_hal_calibration_reason). */
pour_status_t pour_hal_calibration_load(void);

/* Why the last load failed, a pour_cal_status_t (0: it did not). */
int pour_hal_calibration_reason(void);

#endif /* POUR_HAL_CALIBRATION_H */
