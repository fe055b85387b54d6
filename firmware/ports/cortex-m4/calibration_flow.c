/* SPDX-License-Identifier: MIT */
#include "calibration_flow.h"

#include <stddef.h>

void pour_calibration_flow_init(pour_calibration_flow_t *flow, pour_cal_status_t stored, const pour_calibration_t *cal) {
  flow->seen = POUR_MOTOR_CAL_NONE;
  flow->stored = stored;
  if (stored == POUR_CAL_OK && cal != NULL) flow->calibration = *cal;
}

uint8_t pour_calibration_flow_reason(pour_motor_cal_status_t status) {
  switch (status) {
    case POUR_MOTOR_CAL_RESISTANCE: return POUR_CAN_CAL_BAD_RESISTANCE;
    case POUR_MOTOR_CAL_INDUCTANCE: return POUR_CAN_CAL_BAD_INDUCTANCE;
    case POUR_MOTOR_CAL_NO_ENCODER: return POUR_CAN_CAL_NO_ENCODER;
    case POUR_MOTOR_CAL_POLE_PAIRS: return POUR_CAN_CAL_BAD_POLE_PAIRS;
    case POUR_MOTOR_CAL_MOTION: return POUR_CAN_CAL_MOTION_RANGE;
    default: return POUR_CAN_CAL_ABORTED;
  }
}

static void report(pour_calibration_flow_t *flow, pour_can_node_t *node, uint8_t status) {
  pour_can_calibration_result_t r;
  pour_calibration_can_result(flow->stored, &flow->calibration, status, &r);
  pour_can_node_report_calibration(node, &r);
}

/* A good result into flash: the block's new state, and what the bus is told. */
static uint8_t store(pour_calibration_flow_t *flow, pour_can_node_t *node, const pour_drive_t *drv,
                     const pour_flash_t *flash) {
  pour_motor_cal_result_t m;
  (void)pour_drive_calibration(drv, &m);
  const pour_calibration_t c = {m.r_phase_uohm, m.l_phase_nh, m.encoder_direction, m.pole_pairs, m.electrical_offset};
  const pour_cal_status_t st = pour_calibration_save(flash, &c);
  if (st == POUR_CAL_OUT_OF_RANGE) return POUR_CAN_CAL_OUT_OF_RANGE; /* nothing written: the block as it was */
  if (st != POUR_CAL_OK) {
    flow->stored = POUR_CAL_WRITE_FAILED; /* erased or half written: no valid block */
    return POUR_CAN_CAL_WRITE_FAILED;
  }
  flow->stored = POUR_CAL_OK;
  flow->calibration = c;
  if (node->config.identity.init_status == (int8_t)POUR_ECALIBRATION) {
    node->config.identity.init_status = (int8_t)POUR_OK; /* Identity no longer says uncalibrated */
  }
  return POUR_CAN_CAL_OK;
}

bool pour_calibration_flow_tick(pour_calibration_flow_t *flow, pour_can_node_t *node, pour_drive_t *drv, uint8_t mode,
                                const pour_flash_t *flash) {
  if (pour_can_node_take_calibration_start(node) && pour_drive_calibrate(drv) != POUR_OK) {
    report(flow, node, POUR_CAN_CAL_ABORTED); /* the drive does not run: a latched fault, or its offsets */
  }
  if (drv->state == POUR_DRIVE_MEASURING && (mode == (uint8_t)POUR_MODE_ESTOP || mode == (uint8_t)POUR_MODE_RUN)) {
    pour_drive_calibrate_abort(drv);
  }
  const pour_motor_cal_status_t now = pour_drive_calibration(drv, NULL);
  if (flow->seen == POUR_MOTOR_CAL_RUNNING && now != POUR_MOTOR_CAL_RUNNING) {
    report(flow, node, now == POUR_MOTOR_CAL_OK ? store(flow, node, drv, flash) : pour_calibration_flow_reason(now));
  }
  flow->seen = now;
  return drv->state == POUR_DRIVE_MEASURING;
}
