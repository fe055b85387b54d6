/* SPDX-License-Identifier: MIT */
/* The drive's calibration as the board runs it, once a tick after the control step: a CalibrationStart the
 * CAN node accepted (config.can_calibrate) starts the drive's sequence (pour_drive_calibrate: the current-
 * loop interrupt runs it inside pour_drive_isr, which the port calls as always); the e-stop or RUN ends it
 * with the bucket held; a good result is stored through calibration_store, and the outcome goes on the bus
 * unasked: OK, WRITE_FAILED (the flash refused: nothing valid stored, RUN stays refused) or the reason the
 * sequence stopped. The sequence releases the brake for 3.1 s: a start is refused unless the latest sensor
 * sample (the rig's node, over the bus) is recent, in range, shows the output near upright and the
 * rotating bucket empty: a count out of range in the latest sample refuses it, whatever came before. A second start while the sequence runs is answered MEASURING again and changes nothing. */
#ifndef POUR_CALIBRATION_FLOW_H
#define POUR_CALIBRATION_FLOW_H

#include <stdbool.h>
#include <stdint.h>

#include "calibration_store.h"
#include "pour/can_node.h"
#include "pour/drive.h"

#define POUR_CALIBRATION_UPRIGHT_URAD 87266 /* |θ| <= 5°: the sequence's own ±10° then stays within 15° */
#define POUR_CALIBRATION_EMPTY_G 200        /* |rotating scale| <= 200 g: 2 % of the 10 L fill, whose weight at
                                             * the bucket's 12 cm arm and 15° has 0.06 N·m of torque */
#define POUR_CALIBRATION_SAMPLE_MS 20u      /* the latest sample at most this old [ms] (the rig's node sends
                                             * at 1 kHz); older, or none since boot: no data, which is not
                                             * "empty" */

typedef struct {
  pour_motor_cal_status_t seen;   /* the drive's calibration status at the last tick */
  pour_cal_status_t stored;       /* the flash block's state: POUR_CAL_OK is the board's calibration_valid
                                     (board_guard), which RUN needs */
  pour_calibration_t calibration; /* the stored calibration, when stored is POUR_CAL_OK */
  bool stored_now;                /* a measured calibration was stored this tick */
  uint16_t sample_ms;             /* since the latest sensor sample [ms], saturating; UINT16_MAX: none, or the
                                     latest carried a count out of range */
  int32_t theta_urad;             /* its output angle [µrad] */
  int32_t scale_rotating_g;       /* its rotating scale [g] */
} pour_calibration_flow_t;

/* What was loaded at boot (pour_calibration_load's status and, when OK, the block). */
void pour_calibration_flow_init(pour_calibration_flow_t *flow, pour_cal_status_t stored, const pour_calibration_t *cal);

/* Each tick before the node's end_tick: the tick's sensor sample (fresh: it arrived this tick; its encoder
 * count of encoder_bits, 0 = upright) and the interlock's answer to a CalibrationStart into the node
 * (pour_can_node_gate_calibration): MEASURING while the sequence runs or when it may start; else
 * REFUSED_NO_SENSORS, REFUSED_NOT_UPRIGHT, REFUSED_NOT_EMPTY (in that order), or ABORTED when the drive
 * cannot start it (its offsets not measured, or a fault latched that a calibration does not clear). */
void pour_calibration_flow_sense(pour_calibration_flow_t *flow, pour_can_node_t *node, const pour_drive_t *drv,
                                 const pour_sensors_t *sample, bool fresh, uint8_t encoder_bits);

/* One tick (mode: the core's pour_mode_t of this tick). Returns true while the sequence runs: the port then
 * keeps the power stage on and lets the drive's own brake request (released) stand. */
bool pour_calibration_flow_tick(pour_calibration_flow_t *flow, pour_can_node_t *node, pour_drive_t *drv, uint8_t mode,
                                const pour_flash_t *flash);

/* The CAN status of a finished sequence's reason (POUR_CAN_CAL_BAD_RESISTANCE .. _ABORTED). */
uint8_t pour_calibration_flow_reason(pour_motor_cal_status_t status);

#endif /* POUR_CALIBRATION_FLOW_H */
