/* SPDX-License-Identifier: MIT */
/* hal_calibration: the drive's calibration, checked at boot (the board: the block in flash,
 * calibration_store.c). Without a valid one the controller refuses RUN and its Identity frame says why. */
#ifndef POUR_HAL_CALIBRATION_H
#define POUR_HAL_CALIBRATION_H

#include <stdbool.h>

#include "calibration_store.h"
#include "pour/can_codec.h"
#include "pour/fixed.h"

/* Loads and checks the stored calibration: POUR_OK, or POUR_ECALIBRATION (the reason in detail:
 * pour_hal_calibration_reason). */
pour_status_t pour_hal_calibration_load(void);

/* The stored calibration as loaded (the CalibrationResult beside the status the CAN node answers a
 * CalibrationStart with). */
void pour_hal_calibration_result(pour_can_calibration_result_t *result);

/* The block's state as loaded, and its values into *cal when POUR_CAL_OK. */
pour_cal_status_t pour_hal_calibration_stored(pour_calibration_t *cal);

/* The flash that a measured calibration is saved to. */
const pour_flash_t *pour_hal_calibration_flash(void);

/* Whether the stored electrical offset (the electrical angle at the motor encoder's count 0) still holds after
 * this boot: false on the board, whose TIM4 count starts at 0 at every start wherever the rotor stands (RM0440
 * TIMx_CNT reset value 0; encoder_tim4.c) and whose motor encoder has no index (PB8 is the e-stop, UM2516): the
 * offset is found again by a CalibrationStart in each power cycle. */
bool pour_hal_calibration_offset_kept(void);

/* Why the last load failed, a pour_cal_status_t (0: it did not). */
int pour_hal_calibration_reason(void);

#endif /* POUR_HAL_CALIBRATION_H */
