/* SPDX-License-Identifier: MIT */
#include "calibration_flow.h"

#include <stddef.h>

void pour_calibration_flow_init(pour_calibration_flow_t *flow, pour_cal_status_t stored, const pour_calibration_t *cal) {
  flow->seen = POUR_MOTOR_CAL_NONE;
  flow->stored = stored;
  flow->stored_now = false;
  flow->sample_ms = UINT16_MAX; /* none yet */
  flow->theta_urad = flow->scale_rotating_g = 0;
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

void pour_calibration_flow_sense(pour_calibration_flow_t *flow, pour_can_node_t *node, const pour_drive_t *drv,
                                 const pour_sensors_t *sample, bool fresh, uint8_t encoder_bits) {
  if (fresh && sample->encoder >= (1u << encoder_bits)) {
    flow->sample_ms = UINT16_MAX; /* the latest sample is no sample: an older good one does not stand in */
  } else if (fresh) {
    flow->sample_ms = 0u;
    flow->theta_urad = pour_sensors_theta_urad(sample->encoder, encoder_bits);
    flow->scale_rotating_g = sample->scale_rotating_g;
  } else if (flow->sample_ms < UINT16_MAX) {
    flow->sample_ms++;
  }
  uint8_t answer = POUR_CAN_CAL_MEASURING;
  if (drv->state == POUR_DRIVE_MEASURING) {
    answer = POUR_CAN_CAL_MEASURING; /* the one running: the answer stays true, nothing restarts */
  } else if (flow->sample_ms > POUR_CALIBRATION_SAMPLE_MS) {
    answer = POUR_CAN_CAL_REFUSED_NO_SENSORS;
  } else if (flow->theta_urad > POUR_CALIBRATION_UPRIGHT_URAD || flow->theta_urad < -POUR_CALIBRATION_UPRIGHT_URAD) {
    answer = POUR_CAN_CAL_REFUSED_NOT_UPRIGHT;
  } else if (flow->scale_rotating_g > POUR_CALIBRATION_EMPTY_G || flow->scale_rotating_g < -POUR_CALIBRATION_EMPTY_G) {
    answer = POUR_CAN_CAL_REFUSED_NOT_EMPTY;
  } else if (!pour_drive_can_calibrate(drv)) {
    answer = POUR_CAN_CAL_ABORTED;
  }
  pour_can_node_gate_calibration(node, answer);
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
  flow->stored_now = true;
  flow->calibration = c;
  if (node->config.identity.init_status == (int8_t)POUR_ECALIBRATION ||
      node->config.identity.init_status == (int8_t)POUR_EALIGN) {
    node->config.identity.init_status = (int8_t)POUR_OK; /* Identity no longer says uncalibrated, nor unaligned */
  }
  return POUR_CAN_CAL_OK;
}

bool pour_calibration_flow_tick(pour_calibration_flow_t *flow, pour_can_node_t *node, pour_drive_t *drv, uint8_t mode,
                                const pour_flash_t *flash) {
  flow->stored_now = false;
  /* A start the interlock passed; one taken while the sequence runs was answered MEASURING: it stands. */
  if (pour_can_node_take_calibration_start(node) && drv->state != POUR_DRIVE_MEASURING &&
      pour_drive_calibrate(drv) != POUR_OK) {
    report(flow, node, POUR_CAN_CAL_ABORTED); /* the drive changed since the interlock passed it */
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
