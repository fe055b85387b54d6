/* SPDX-License-Identifier: MIT */
#include "board_loop.h"

#include <stdbool.h>

#include "board_drive.h"
#include "board_params.h"
#include "calibration_flow.h"
#include "clock.h"
#include "hal_calibration.h"
#include "hal_can.h"
#include "hal_estop.h"
#include "hal_led.h"

static pour_calibration_flow_t flow;
static pour_can_node_t *flow_node;

/* The drive's tick calls it after the core's step: a good result stored makes the calibration valid. */
static bool calibration_tick(pour_drive_t *drv, uint8_t mode) {
  const bool measuring = pour_calibration_flow_tick(&flow, flow_node, drv, mode, pour_hal_calibration_flash());
  if (flow.stored_now) {
    pour_board_drive_calibrated();
  }
  return measuring;
}

void pour_board_loop_init(pour_can_node_t *node) {
  pour_calibration_t cal;
  const pour_cal_status_t stored = pour_hal_calibration_stored(&cal);
  pour_calibration_flow_init(&flow, stored, &cal);
  flow_node = node;
  pour_board_drive_set_calibration(calibration_tick);
}

/* The FDCAN's TX FIFO holds 3 frames (the STM32G4's fixed message RAM, RM0440 "FDCAN message RAM": 3 Tx
 * buffers; fdcan.h), each on the bus for 111 bit times, while a heartbeat tick queues 4 at once (torque,
 * heartbeat, identity, drive telemetry) and a calibration's outcome a 5th: what does not fit waits for the next
 * tick's transmit, ahead of that tick's own frames and in order (the virtual board found DriveTelemetry never
 * sent: docs/virtual-board.md). Full, the backlog drops the newest. */
static pour_can_frame_t backlog[POUR_CAN_NODE_MAX_TX];
static uint8_t backlog_n;

void pour_board_transmit(const pour_can_frame_t *tx, uint8_t n) {
  uint8_t kept = 0u;
  for (uint8_t i = 0; i < backlog_n; ++i) {
    if (kept == 0u && pour_hal_can_transmit(&backlog[i]) >= 0) {
      continue;
    }
    backlog[kept++] = backlog[i];
  }
  for (uint8_t i = 0; i < n; ++i) {
    if (kept == 0u && pour_hal_can_transmit(&tx[i]) >= 0) {
      continue;
    }
    if (kept < POUR_CAN_NODE_MAX_TX) {
      backlog[kept++] = tx[i];
    }
  }
  backlog_n = kept;
}

void pour_board_loop_tick(pour_control_t *ctl, pour_can_node_t *node, uint32_t overruns) {
  /* The hardwired line around the tick's frames: a clear counts only if the line was released at both. */
  pour_can_node_estop_line(node, pour_hal_estop_asserted());
  pour_hal_can_poll();
  pour_can_frame_t f;
  while (pour_hal_can_receive(&f) == 1) {
    (void)pour_can_node_receive(node, &f);
  }
  pour_can_node_estop_line(node, pour_hal_estop_asserted());
  pour_control_input_t in;
  pour_can_node_begin_tick(node, &in);
  pour_board_params_correct(&in.sensors); /* the encoder's zero, the scales' tares and factors */
  /* An ExperimentStart goes to the core before the tick; this tick's update answers it. */
  uint8_t kind = 0u;
  const bool asked = pour_can_node_take_experiment(node, &kind);
  if (asked) {
    pour_control_experiment(ctl, kind);
  }
  pour_board_params_service(ctl, node); /* before the step, which then runs on the set in force */
  pour_control_output_t out;
  pour_board_drive_tick(ctl, &in, &out);
  pour_calibration_flow_sense(&flow, node, pour_board_drive_state(), &in.sensors, in.sensors_fresh,
                              ctl->config.sensors.encoder_bits);
  pour_hal_led_show(out.mode, false);
  pour_can_drive_telemetry_t drive;
  pour_board_drive_telemetry(&drive);
  drive.crystal_4mhz = (uint8_t)(pour_clock_crystal() / 4000000u);
  pour_can_node_set_drive(node, &drive);
  pour_can_node_set_held(node, pour_control_held(ctl)); /* the heartbeat's Held: RUN waits for a Reset */
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  pour_board_transmit(tx, pour_can_node_end_tick(node, &out, overruns, tx));
  pour_can_frame_t ack;
  if (asked && pour_can_node_experiment_ack(node, kind, pour_control_experiment_answer(ctl), &ack) == POUR_OK) {
    pour_board_transmit(&ack, 1u);
  }
}
