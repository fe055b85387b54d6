/* SPDX-License-Identifier: MIT */
#include "pour/can_codec.h"

#include <stddef.h>

/* Little-endian field access. Signed fields are assembled as unsigned and sign-extended explicitly,
 * so no shift ever touches a negative value. */
static void put_u16(uint8_t *p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}

static void put_u24(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)((v >> 8) & 0xFFu);
  p[2] = (uint8_t)((v >> 16) & 0xFFu);
}

static void put_u32(uint8_t *p, uint32_t v) {
  put_u16(p, (uint16_t)(v & 0xFFFFu));
  put_u16(p + 2, (uint16_t)(v >> 16));
}

static uint16_t get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (uint16_t)(p[1] << 8)); }

static uint32_t get_u24(const uint8_t *p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16);
}

static uint32_t get_u32(const uint8_t *p) { return (uint32_t)get_u16(p) | ((uint32_t)get_u16(p + 2) << 16); }

/* Two's complement reinterpretation without implementation-defined conversion. */
static int16_t as_i16(uint16_t v) { return (int16_t)((v & 0x8000u) ? -(int32_t)(uint16_t)(~v) - 1 : (int32_t)v); }

static uint16_t i16_bits(int16_t v) { return (uint16_t)((uint32_t)(int32_t)v & 0xFFFFu); }

static void frame_begin(pour_can_frame_t *frame, uint8_t node_id, uint8_t cmd, uint8_t dlc) {
  frame->id = pour_can_id(node_id, cmd);
  frame->dlc = dlc;
  for (size_t i = 0; i < sizeof frame->data; ++i) {
    frame->data[i] = 0;
  }
}

/* int16_t reaches 32767 = POUR_CAN_SCALE_MAX_G: only the overload code -32768 is out of range. */
static int scale_ok(int16_t g) { return g >= -POUR_CAN_SCALE_MAX_G; }

pour_status_t pour_can_pack_sensors(uint8_t node_id, const pour_can_sensors_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || msg->encoder > POUR_CAN_ENCODER_MAX ||
      !scale_ok(msg->scale_rotating_g) || !scale_ok(msg->scale_target_g)) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_SENSORS, POUR_CAN_DLC_SENSORS);
  frame->data[0] = msg->seq_low;
  put_u24(&frame->data[1], msg->encoder);
  put_u16(&frame->data[4], i16_bits(msg->scale_rotating_g));
  put_u16(&frame->data[6], i16_bits(msg->scale_target_g));
  return POUR_OK;
}

pour_status_t pour_can_pack_torque(uint8_t node_id, const pour_can_torque_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || msg->action > POUR_CAN_ACTION_MAX ||
      msg->mode > POUR_CAN_MODE_MAX || msg->limits > POUR_CAN_LIMITS_MAX) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_TORQUE, POUR_CAN_DLC_TORQUE);
  put_u16(&frame->data[0], msg->seq);
  put_u16(&frame->data[2], i16_bits(msg->torque));
  frame->data[4] = msg->action;
  frame->data[5] = msg->mode;
  frame->data[6] = msg->limits;
  return POUR_OK;
}

pour_status_t pour_can_pack_heartbeat(uint8_t node_id, const pour_can_heartbeat_t *msg,
                                      pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || msg->mode > POUR_CAN_MODE_MAX ||
      msg->refused > POUR_CAN_REFUSED_MAX || msg->held > 1u) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_HEARTBEAT, POUR_CAN_DLC_HEARTBEAT);
  frame->data[0] = (uint8_t)(msg->mode | (uint8_t)(msg->refused << 4));
  /* Faults occupy bits 8..23: the core's bits in byte 1, the CAN node's in byte 2. */
  uint16_t faults = (uint16_t)(msg->faults & POUR_CAN_HEARTBEAT_FAULT_MASK);
  put_u16(&frame->data[1], faults);
  frame->data[2] = (uint8_t)(frame->data[2] | (uint8_t)(msg->held << 7)); /* Held: bit 23, above every fault */
  put_u16(&frame->data[3], msg->rx_dropped);
  put_u16(&frame->data[5], msg->overruns);
  frame->data[7] = msg->counter;
  return POUR_OK;
}

pour_status_t pour_can_pack_estop(uint8_t node_id, const pour_can_estop_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || msg->assert_estop > 1u) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_ESTOP, POUR_CAN_DLC_ESTOP);
  frame->data[0] = msg->assert_estop;
  return POUR_OK;
}

pour_status_t pour_can_pack_identity(uint8_t node_id, const pour_can_identity_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || msg->init_status > 0) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_IDENTITY, POUR_CAN_DLC_IDENTITY);
  put_u32(&frame->data[0], msg->weights_hash);
  put_u16(&frame->data[4], msg->tau_max_cnm);
  frame->data[6] = msg->fw_version;
  frame->data[7] = (uint8_t)((uint32_t)(int32_t)msg->init_status & 0xFFu);
  return POUR_OK;
}

static int calibration_ok(const pour_can_calibration_result_t *m) {
  return m->status <= POUR_CAN_CAL_STATUS_MAX && m->stored <= POUR_CAN_CAL_STORED_MAX && m->encoder_reversed <= 1u &&
         m->pole_pairs <= POUR_CAN_POLE_PAIRS_MAX;
}

pour_status_t pour_can_pack_calibration_result(uint8_t node_id, const pour_can_calibration_result_t *msg,
                                               pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || !calibration_ok(msg)) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_CALIBRATION_RESULT, POUR_CAN_DLC_CALIBRATION_RESULT);
  frame->data[0] = (uint8_t)(msg->status | (uint8_t)(msg->stored << 5));
  frame->data[1] = msg->encoder_reversed;
  frame->data[2] = msg->pole_pairs;
  put_u16(&frame->data[3], msg->resistance_mohm);
  put_u16(&frame->data[5], msg->inductance_uh);
  frame->data[7] = msg->electrical_offset;
  return POUR_OK;
}

static int current_ok(int16_t i) { return i >= -POUR_CAN_CURRENT_MAX; }

#define DRIVE_CRYSTAL_SHIFT 11u /* DriveTelemetry.Crystal above the 11 fault bits in bytes 6..7 */

pour_status_t pour_can_pack_drive_telemetry(uint8_t node_id, const pour_can_drive_telemetry_t *msg,
                                            pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || !current_ok(msg->id_2ma) ||
      !current_ok(msg->iq_2ma) || msg->crystal_4mhz > POUR_CAN_CRYSTAL_MAX) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_DRIVE_TELEMETRY, POUR_CAN_DLC_DRIVE_TELEMETRY);
  put_u16(&frame->data[0], i16_bits(msg->id_2ma));
  put_u16(&frame->data[2], i16_bits(msg->iq_2ma));
  put_u16(&frame->data[4], msg->vbus_mv);
  put_u16(&frame->data[6], (uint16_t)((msg->drive_faults & POUR_CAN_DRIVE_FAULT_MASK) |
                                      ((uint32_t)msg->crystal_4mhz << DRIVE_CRYSTAL_SHIFT)));
  return POUR_OK;
}

pour_status_t pour_can_pack_param_read(uint8_t node_id, const pour_can_param_read_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_PARAM_READ, POUR_CAN_DLC_PARAM_READ);
  frame->data[0] = msg->param_id;
  return POUR_OK;
}

static int is_param_cmd(uint8_t cmd) { return cmd == POUR_CAN_CMD_PARAM_VALUE || cmd == POUR_CAN_CMD_PARAM_WRITE; }

pour_status_t pour_can_pack_param(uint8_t node_id, uint8_t cmd, const pour_can_param_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || !is_param_cmd(cmd)) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, cmd, POUR_CAN_DLC_PARAM_VALUE);
  frame->data[0] = msg->param_id;
  put_u32(&frame->data[1], (uint32_t)msg->value);
  return POUR_OK;
}

pour_status_t pour_can_pack_param_ack(uint8_t node_id, const pour_can_param_ack_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || msg->request > POUR_CAN_CMD_MASK ||
      msg->result > POUR_CAN_PARAM_RESULT_MAX) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_PARAM_ACK, POUR_CAN_DLC_PARAM_ACK);
  frame->data[0] = msg->request;
  frame->data[1] = msg->param_id;
  frame->data[2] = msg->result;
  return POUR_OK;
}

static int tare_ok(uint8_t scales) { return scales >= 1u && scales <= (POUR_CAN_TARE_ROTATING | POUR_CAN_TARE_TARGET); }

pour_status_t pour_can_pack_tare(uint8_t node_id, const pour_can_tare_t *msg, pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || !tare_ok(msg->scales)) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_TARE, POUR_CAN_DLC_TARE);
  frame->data[0] = msg->scales;
  return POUR_OK;
}

static int kind_ok(uint8_t kind) { return kind >= POUR_CAN_EXPERIMENT_KIND_MIN && kind <= POUR_CAN_EXPERIMENT_KIND_MAX; }

pour_status_t pour_can_pack_experiment_start(uint8_t node_id, const pour_can_experiment_start_t *msg,
                                             pour_can_frame_t *frame) {
  if (msg == NULL || frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || !kind_ok(msg->kind)) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, POUR_CAN_CMD_EXPERIMENT_START, POUR_CAN_DLC_EXPERIMENT_START);
  frame->data[0] = msg->kind;
  return POUR_OK;
}

static int is_signal_free_command(uint8_t cmd) {
  return cmd == POUR_CAN_CMD_CLEAR_ERRORS || cmd == POUR_CAN_CMD_STOP || cmd == POUR_CAN_CMD_RESET ||
         cmd == POUR_CAN_CMD_CALIBRATION_START || cmd == POUR_CAN_CMD_PARAM_SAVE || cmd == POUR_CAN_CMD_ZERO ||
         cmd == POUR_CAN_CMD_CALIBRATION_READ;
}

pour_status_t pour_can_pack_command(uint8_t node_id, uint8_t cmd, pour_can_frame_t *frame) {
  if (frame == NULL || node_id > POUR_CAN_NODE_ID_MAX || !is_signal_free_command(cmd)) {
    return POUR_EINVAL;
  }
  frame_begin(frame, node_id, cmd, 0u);
  return POUR_OK;
}

int pour_can_dlc_of(uint8_t cmd) {
  switch (cmd) {
    case POUR_CAN_CMD_HEARTBEAT: return (int)POUR_CAN_DLC_HEARTBEAT;
    case POUR_CAN_CMD_ESTOP: return (int)POUR_CAN_DLC_ESTOP;
    case POUR_CAN_CMD_STOP: return (int)POUR_CAN_DLC_STOP;
    case POUR_CAN_CMD_IDENTITY: return (int)POUR_CAN_DLC_IDENTITY;
    case POUR_CAN_CMD_CALIBRATION_START: return (int)POUR_CAN_DLC_CALIBRATION_START;
    case POUR_CAN_CMD_CALIBRATION_RESULT: return (int)POUR_CAN_DLC_CALIBRATION_RESULT;
    case POUR_CAN_CMD_CALIBRATION_READ: return (int)POUR_CAN_DLC_CALIBRATION_READ;
    case POUR_CAN_CMD_DRIVE_TELEMETRY: return (int)POUR_CAN_DLC_DRIVE_TELEMETRY;
    case POUR_CAN_CMD_RESET: return (int)POUR_CAN_DLC_RESET;
    case POUR_CAN_CMD_SENSORS: return (int)POUR_CAN_DLC_SENSORS;
    case POUR_CAN_CMD_TORQUE: return (int)POUR_CAN_DLC_TORQUE;
    case POUR_CAN_CMD_CLEAR_ERRORS: return (int)POUR_CAN_DLC_CLEAR_ERRORS;
    case POUR_CAN_CMD_PARAM_READ: return (int)POUR_CAN_DLC_PARAM_READ;
    case POUR_CAN_CMD_PARAM_VALUE: return (int)POUR_CAN_DLC_PARAM_VALUE;
    case POUR_CAN_CMD_PARAM_WRITE: return (int)POUR_CAN_DLC_PARAM_WRITE;
    case POUR_CAN_CMD_PARAM_SAVE: return (int)POUR_CAN_DLC_PARAM_SAVE;
    case POUR_CAN_CMD_PARAM_ACK: return (int)POUR_CAN_DLC_PARAM_ACK;
    case POUR_CAN_CMD_TARE: return (int)POUR_CAN_DLC_TARE;
    case POUR_CAN_CMD_ZERO: return (int)POUR_CAN_DLC_ZERO;
    case POUR_CAN_CMD_EXPERIMENT_START: return (int)POUR_CAN_DLC_EXPERIMENT_START;
    default: return -1;
  }
}

/* Checks that frame carries cmd with its DLC. */
static pour_can_rx_t check_header(const pour_can_frame_t *frame, uint8_t cmd) {
  if (frame == NULL || frame->id > POUR_CAN_STD_ID_MAX || (frame->id & POUR_CAN_CMD_MASK) != cmd) {
    return POUR_CAN_RX_BAD_ID;
  }
  if (frame->dlc != (uint8_t)pour_can_dlc_of(cmd)) {
    return POUR_CAN_RX_BAD_DLC;
  }
  return POUR_CAN_RX_OK;
}

/* check_header, and a place to unpack into. */
static pour_can_rx_t check_unpack(const pour_can_frame_t *frame, uint8_t cmd, const void *msg) {
  const pour_can_rx_t rc = check_header(frame, cmd);
  return rc != POUR_CAN_RX_OK ? rc : (msg == NULL ? POUR_CAN_RX_BAD_ID : POUR_CAN_RX_OK);
}

pour_can_rx_t pour_can_unpack_sensors(const pour_can_frame_t *frame, pour_can_sensors_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_SENSORS, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  const int16_t rot = as_i16(get_u16(&frame->data[4]));
  const int16_t tgt = as_i16(get_u16(&frame->data[6]));
  if (!scale_ok(rot) || !scale_ok(tgt)) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->seq_low = frame->data[0];
  msg->encoder = get_u24(&frame->data[1]);
  msg->scale_rotating_g = rot;
  msg->scale_target_g = tgt;
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_torque(const pour_can_frame_t *frame, pour_can_torque_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_TORQUE, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if (frame->data[4] > POUR_CAN_ACTION_MAX || frame->data[5] > POUR_CAN_MODE_MAX ||
      frame->data[6] > POUR_CAN_LIMITS_MAX) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->seq = get_u16(&frame->data[0]);
  msg->torque = as_i16(get_u16(&frame->data[2]));
  msg->action = frame->data[4];
  msg->mode = frame->data[5];
  msg->limits = frame->data[6];
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_heartbeat(const pour_can_frame_t *frame, pour_can_heartbeat_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_HEARTBEAT, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if ((frame->data[0] & 0x0Fu) > POUR_CAN_MODE_MAX) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->mode = (uint8_t)(frame->data[0] & 0x0Fu);
  msg->refused = (uint8_t)(frame->data[0] >> 4);
  msg->faults = (uint16_t)(get_u16(&frame->data[1]) & POUR_CAN_HEARTBEAT_FAULT_MASK);
  msg->held = (uint8_t)(frame->data[2] >> 7);
  msg->rx_dropped = get_u16(&frame->data[3]);
  msg->overruns = get_u16(&frame->data[5]);
  msg->counter = frame->data[7];
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_estop(const pour_can_frame_t *frame, pour_can_estop_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_ESTOP, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if (frame->data[0] > 1u) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->assert_estop = frame->data[0];
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_identity(const pour_can_frame_t *frame, pour_can_identity_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_IDENTITY, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if ((frame->data[7] & 0x80u) == 0u && frame->data[7] != 0u) {
    return POUR_CAN_RX_OUT_OF_RANGE; /* a positive status does not exist */
  }
  msg->weights_hash = get_u32(&frame->data[0]);
  msg->tau_max_cnm = get_u16(&frame->data[4]);
  msg->fw_version = frame->data[6];
  msg->init_status = (int8_t)((int32_t)frame->data[7] - ((frame->data[7] & 0x80u) ? 256 : 0));
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_param_read(const pour_can_frame_t *frame, pour_can_param_read_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_PARAM_READ, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  msg->param_id = frame->data[0];
  return POUR_CAN_RX_OK;
}

static int32_t as_i32(uint32_t v) { return (v & 0x80000000u) ? -(int32_t)(~v) - 1 : (int32_t)v; }

pour_can_rx_t pour_can_unpack_param(const pour_can_frame_t *frame, uint8_t cmd, pour_can_param_t *msg) {
  const pour_can_rx_t rc = is_param_cmd(cmd) ? check_unpack(frame, cmd, msg) : POUR_CAN_RX_BAD_ID;
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  msg->param_id = frame->data[0];
  msg->value = as_i32(get_u32(&frame->data[1]));
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_param_ack(const pour_can_frame_t *frame, pour_can_param_ack_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_PARAM_ACK, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if (frame->data[0] > POUR_CAN_CMD_MASK || frame->data[2] > POUR_CAN_PARAM_RESULT_MAX) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->request = frame->data[0];
  msg->param_id = frame->data[1];
  msg->result = frame->data[2];
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_tare(const pour_can_frame_t *frame, pour_can_tare_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_TARE, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if (!tare_ok(frame->data[0])) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->scales = frame->data[0];
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_experiment_start(const pour_can_frame_t *frame, pour_can_experiment_start_t *msg) {
  const pour_can_rx_t rc = check_unpack(frame, POUR_CAN_CMD_EXPERIMENT_START, msg);
  if (rc != POUR_CAN_RX_OK) {
    return rc;
  }
  if (!kind_ok(frame->data[0])) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->kind = frame->data[0];
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_command(const pour_can_frame_t *frame, uint8_t cmd) {
  return is_signal_free_command(cmd) ? check_header(frame, cmd) : POUR_CAN_RX_BAD_ID;
}

pour_can_rx_t pour_can_classify(const pour_can_frame_t *frame, uint8_t node_id, uint32_t accept_mask,
                                uint8_t *cmd) {
  if (frame == NULL || frame->id > POUR_CAN_STD_ID_MAX) {
    return POUR_CAN_RX_BAD_ID;
  }
  if ((frame->id >> POUR_CAN_NODE_SHIFT) != node_id) {
    return POUR_CAN_RX_OTHER_NODE;
  }
  uint8_t c = (uint8_t)(frame->id & POUR_CAN_CMD_MASK);
  if (cmd != NULL) {
    *cmd = c;
  }
  int dlc = pour_can_dlc_of(c);
  if (dlc < 0 || (accept_mask & (1u << c)) == 0u) {
    return POUR_CAN_RX_BAD_ID;
  }
  return frame->dlc == (uint8_t)dlc ? POUR_CAN_RX_OK : POUR_CAN_RX_BAD_DLC;
}

pour_can_rx_t pour_can_unpack_calibration_result(const pour_can_frame_t *frame, pour_can_calibration_result_t *msg) {
  pour_can_rx_t rc = check_header(frame, POUR_CAN_CMD_CALIBRATION_RESULT);
  if (rc != POUR_CAN_RX_OK || msg == NULL) {
    return rc != POUR_CAN_RX_OK ? rc : POUR_CAN_RX_BAD_ID;
  }
  pour_can_calibration_result_t m;
  m.status = (uint8_t)(frame->data[0] & 0x1Fu);
  m.stored = (uint8_t)(frame->data[0] >> 5);
  m.encoder_reversed = (uint8_t)(frame->data[1] & 1u); /* bits 9..15 are not signals */
  m.pole_pairs = frame->data[2];
  m.resistance_mohm = get_u16(&frame->data[3]);
  m.inductance_uh = get_u16(&frame->data[5]);
  m.electrical_offset = frame->data[7];
  if (!calibration_ok(&m)) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  *msg = m;
  return POUR_CAN_RX_OK;
}

pour_can_rx_t pour_can_unpack_drive_telemetry(const pour_can_frame_t *frame, pour_can_drive_telemetry_t *msg) {
  pour_can_rx_t rc = check_header(frame, POUR_CAN_CMD_DRIVE_TELEMETRY);
  if (rc != POUR_CAN_RX_OK || msg == NULL) {
    return rc != POUR_CAN_RX_OK ? rc : POUR_CAN_RX_BAD_ID;
  }
  const int16_t id = as_i16(get_u16(&frame->data[0]));
  const int16_t iq = as_i16(get_u16(&frame->data[2]));
  const uint16_t word = get_u16(&frame->data[6]);
  const uint8_t crystal = (uint8_t)((word >> DRIVE_CRYSTAL_SHIFT) & 0xFu);
  if (!current_ok(id) || !current_ok(iq) || crystal > POUR_CAN_CRYSTAL_MAX) {
    return POUR_CAN_RX_OUT_OF_RANGE;
  }
  msg->id_2ma = id;
  msg->iq_2ma = iq;
  msg->vbus_mv = get_u16(&frame->data[4]);
  msg->drive_faults = (uint16_t)(word & POUR_CAN_DRIVE_FAULT_MASK);
  msg->crystal_4mhz = crystal;
  return POUR_CAN_RX_OK;
}
