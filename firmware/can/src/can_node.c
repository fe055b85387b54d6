/* SPDX-License-Identifier: MIT */
#include "pour/can_node.h"

#include <stddef.h>

#include "pour/params.h"

/* Commands a controller accepts; HEARTBEAT, IDENTITY and TORQUE are its own transmissions. */
#define PARAM_MASK ((1u << POUR_CAN_CMD_PARAM_READ) | (1u << POUR_CAN_CMD_PARAM_WRITE) | \
                    (1u << POUR_CAN_CMD_PARAM_SAVE) | (1u << POUR_CAN_CMD_TARE) | (1u << POUR_CAN_CMD_ZERO))
#define ACCEPT_MASK ((1u << POUR_CAN_CMD_ESTOP) | (1u << POUR_CAN_CMD_STOP) | (1u << POUR_CAN_CMD_SENSORS) | \
                     (1u << POUR_CAN_CMD_CLEAR_ERRORS) | (1u << POUR_CAN_CMD_RESET) |                             \
                     (1u << POUR_CAN_CMD_CALIBRATION_START) | (1u << POUR_CAN_CMD_EXPERIMENT_START) | PARAM_MASK | \
                     (1u << POUR_CAN_CMD_CALIBRATION_READ))

pour_can_node_config_t pour_can_node_default_config(void) {
  pour_can_node_config_t c;
  c.node_id = 0;
  c.watchdog_ms = 50;
  c.heartbeat_period_ms = 100;
  c.identity.weights_hash = 0u;
  c.identity.tau_max_cnm = 0u;
  c.identity.fw_version = (uint8_t)POUR_FIRMWARE_VERSION;
  c.identity.init_status = (int8_t)POUR_OK;
  c.can_calibrate = false;
  return c;
}

pour_status_t pour_can_node_init(pour_can_node_t *node, const pour_can_node_config_t *config) {
  if (node == NULL || config == NULL || config->node_id > POUR_CAN_NODE_ID_MAX || config->watchdog_ms == 0u ||
      config->heartbeat_period_ms == 0u || config->identity.init_status > 0) {
    return POUR_EINVAL;
  }
  pour_can_node_t zero = {0};
  *node = zero;
  node->config = *config;
  node->ms_to_heartbeat = 0;
  pour_commands_init(&node->commands);
  node->calibration.status = POUR_CAN_CAL_UNAVAILABLE;
  node->calibration.stored = POUR_CAN_CAL_EMPTY;
  node->calibration_gate = POUR_CAN_CAL_MEASURING;
  return POUR_OK;
}

static void count(uint32_t *c) {
  if (*c != UINT32_MAX) {
    ++*c;
  }
}

/* A valid sample or command feeds the watchdog; only a sample arms it. The watchdog guards the sample
 * stream a pour runs on (RUN needs fresh samples), so an idle node that has never had one, a bench with no
 * host stream, answers its e-stop and its clear without tripping; once samples have come, silence trips. */
static void kick(pour_can_node_t *node) {
  node->ms_since_valid = 0;
}

static pour_can_rx_t drop(pour_can_node_t *node, pour_can_rx_t why) {
  switch (why) {
    case POUR_CAN_RX_BAD_DLC: count(&node->counters.bad_dlc); break;
    case POUR_CAN_RX_OUT_OF_RANGE: count(&node->counters.out_of_range); break;
    case POUR_CAN_RX_OTHER_NODE: count(&node->counters.other_node); break;
    default: count(&node->counters.bad_id); break;
  }
  return why;
}

/* Takes a sample: the frame's 8-bit seq continues the 32-bit count by its forward distance (mod 2^8), so
 * a wrap is the next sample and a repeated frame repeats the seq (the core's supervisor sees it). The
 * readings go to the core as the sensors gave them; the estimator judges them (BAD_INPUT). */
static void take_sample(pour_can_node_t *node, const pour_can_sensors_t *m) {
  const uint8_t last8 = (uint8_t)(node->sensors.seq & 0xFFu);
  node->sensors.seq = node->have_seq ? node->sensors.seq + (uint8_t)(m->seq_low - last8) : m->seq_low;
  node->have_seq = true;
  node->sensors.encoder = m->encoder;
  node->sensors.scale_rotating_g = m->scale_rotating_g;
  node->sensors.scale_target_g = m->scale_target_g;
  node->sensors_fresh = true;
}

/* A parameter request, unpacked; the port answers it outside the tick. Not a command of the control loop:
 * it does not feed the watchdog. */
static pour_can_rx_t take_param_request(pour_can_node_t *node, const pour_can_frame_t *frame, uint8_t cmd) {
  pour_can_param_request_t r = {.cmd = cmd, .param_id = 0u, .value = 0, .scales = 0u};
  pour_can_rx_t rc = POUR_CAN_RX_OK;
  if (cmd == POUR_CAN_CMD_PARAM_READ) {
    pour_can_param_read_t m;
    rc = pour_can_unpack_param_read(frame, &m);
    r.param_id = m.param_id;
  } else if (cmd == POUR_CAN_CMD_PARAM_WRITE) {
    pour_can_param_t m;
    rc = pour_can_unpack_param(frame, cmd, &m);
    r.param_id = m.param_id;
    r.value = m.value;
  } else if (cmd == POUR_CAN_CMD_TARE) {
    pour_can_tare_t m;
    rc = pour_can_unpack_tare(frame, &m);
    r.scales = m.scales;
  }
  if (rc != POUR_CAN_RX_OK) {
    return drop(node, rc);
  }
  if (node->param_pending) {
    count(&node->counters.param_busy);
    return POUR_CAN_RX_BUSY;
  }
  node->param_request = r;
  node->param_pending = true;
  count(&node->counters.accepted);
  return POUR_CAN_RX_OK;
}

bool pour_can_node_take_param_request(pour_can_node_t *node, pour_can_param_request_t *request) {
  if (!node->param_pending) {
    return false;
  }
  *request = node->param_request;
  node->param_pending = false;
  return true;
}

pour_can_rx_t pour_can_node_receive(pour_can_node_t *node, const pour_can_frame_t *frame) {
  if (node == NULL) {
    return POUR_CAN_RX_BAD_ID;
  }
  uint8_t cmd = 0;
  pour_can_rx_t rc = pour_can_classify(frame, node->config.node_id, ACCEPT_MASK, &cmd);
  if (rc != POUR_CAN_RX_OK) {
    return drop(node, rc);
  }
  if ((PARAM_MASK & (1u << cmd)) != 0u) {
    return take_param_request(node, frame, cmd);
  }
  switch (cmd) {
    case POUR_CAN_CMD_SENSORS: {
      pour_can_sensors_t m;
      rc = pour_can_unpack_sensors(frame, &m);
      if (rc != POUR_CAN_RX_OK) {
        return drop(node, rc);
      }
      take_sample(node, &m);
      node->armed = true;
      kick(node);
      break;
    }
    case POUR_CAN_CMD_ESTOP: {
      pour_can_estop_t e;
      rc = pour_can_unpack_estop(frame, &e);
      if (rc != POUR_CAN_RX_OK) {
        return drop(node, rc);
      }
      pour_commands_estop(&node->commands, POUR_ESTOP_BUS, e.assert_estop != 0u);
      kick(node);
      break;
    }
    case POUR_CAN_CMD_STOP: /* classify checked the DLC of these three: they have no signals */
      pour_commands_stop(&node->commands);
      kick(node);
      break;
    case POUR_CAN_CMD_RESET:
      pour_commands_reset(&node->commands);
      kick(node);
      break;
    case POUR_CAN_CMD_EXPERIMENT_START: {
      pour_can_experiment_start_t m;
      rc = pour_can_unpack_experiment_start(frame, &m);
      if (rc != POUR_CAN_RX_OK) {
        return drop(node, rc);
      }
      node->experiment_requested = true;
      node->experiment_kind = m.kind;
      kick(node);
      break;
    }
    case POUR_CAN_CMD_CALIBRATION_START: /* answered, or refused with its reason, at the end of the tick */
      node->calibration_requested = true;
      kick(node);
      break;
    case POUR_CAN_CMD_CALIBRATION_READ: /* a query, like a parameter read: no command, no watchdog feed */
      node->calibration_read = true;
      break;
    default: /* POUR_CAN_CMD_CLEAR_ERRORS */
      pour_commands_clear(&node->commands);
      kick(node);
      break;
  }
  count(&node->counters.accepted);
  return POUR_CAN_RX_OK;
}

static bool tripped(const pour_can_node_t *node) {
  return node->armed && node->ms_since_valid > node->config.watchdog_ms;
}

void pour_can_node_estop_line(pour_can_node_t *node, bool asserted) {
  pour_commands_estop(&node->commands, POUR_ESTOP_LINE, asserted);
}

void pour_can_node_begin_tick(pour_can_node_t *node, pour_control_input_t *in) {
  in->sensors_fresh = node->sensors_fresh;
  in->sensors = node->sensors;
  pour_commands_take(&node->commands, in);
  in->link_fault = tripped(node);
  in->drive_faults = 0u; /* the bus carries no drive: a port with one of its own fills these in */
  in->drive_trusted = true;
  node->sensors_fresh = false;
}

bool pour_can_node_watchdog(pour_can_node_t *node, uint32_t elapsed_ms) {
  if (node->armed) {
    uint64_t t = (uint64_t)node->ms_since_valid + elapsed_ms;
    node->ms_since_valid = t > UINT32_MAX ? UINT32_MAX : (uint32_t)t;
  }
  return tripped(node);
}

uint32_t pour_can_node_dropped(const pour_can_node_t *node) {
  const pour_can_node_counters_t *c = &node->counters;
  uint64_t sum = (uint64_t)c->bad_id + c->bad_dlc + c->out_of_range + c->param_busy;
  return sum > UINT32_MAX ? UINT32_MAX : (uint32_t)sum;
}

pour_status_t pour_can_node_torque_frame(const pour_can_node_t *node, const pour_control_output_t *out,
                                         pour_can_frame_t *frame) {
  pour_can_torque_t t;
  t.seq = (uint16_t)(node->sensors.seq & 0xFFFFu);
  t.torque = out->torque;
  t.action = (uint8_t)(out->action & POUR_CAN_ACTION_MAX);
  t.mode = (uint8_t)(out->mode & POUR_CAN_MODE_MAX);
  t.limits = (uint8_t)(out->limits & POUR_CAN_LIMITS_MAX);
  return pour_can_pack_torque(node->config.node_id, &t, frame);
}

uint8_t pour_can_node_status_frames(pour_can_node_t *node, const pour_control_output_t *out, uint32_t overruns,
                                    pour_can_frame_t tx[2]) {
  pour_can_heartbeat_t hb;
  hb.mode = (uint8_t)(out->mode & POUR_CAN_MODE_MAX);
  hb.faults = out->faults;
  hb.rx_dropped = (uint16_t)(pour_can_node_dropped(node) & 0xFFFFu);
  hb.overruns = (uint16_t)(overruns & 0xFFFFu);
  hb.counter = node->heartbeat_counter;
  hb.held = node->held ? 1u : 0u; /* in FAULT too: a clear then leaves the axis held, awaiting a Reset */
  hb.refused = (uint8_t)((out->refused + node->commands.clears_dropped) & POUR_CAN_REFUSED_MAX);
  if (pour_can_pack_heartbeat(node->config.node_id, &hb, &tx[0]) != POUR_OK ||
      pour_can_pack_identity(node->config.node_id, &node->config.identity, &tx[1]) != POUR_OK) {
    return 0u;
  }
  node->heartbeat_counter++;
  return 2u;
}

bool pour_can_node_calibration_frame(pour_can_node_t *node, uint8_t mode, pour_can_frame_t *frame) {
  pour_can_calibration_result_t r = node->calibration;
  if (node->calibration_requested) {
    node->calibration_requested = false;
    if (mode == (uint8_t)POUR_MODE_RUN) {
      r.status = POUR_CAN_CAL_REFUSED_RUNNING;
    } else if (mode == (uint8_t)POUR_MODE_ESTOP) {
      r.status = POUR_CAN_CAL_REFUSED_ESTOP;
    } else if (node->config.can_calibrate) {
      r.status = node->calibration_gate;
      node->calibration_start = node->calibration_start || r.status == POUR_CAN_CAL_MEASURING;
    }
  } else if (node->calibration_report) {
    node->calibration_report = false;
  } else if (node->calibration_read) {
    node->calibration_read = false;
    r.status = node->config.can_calibrate ? POUR_CAN_CAL_STORED : POUR_CAN_CAL_UNAVAILABLE;
  } else {
    return false;
  }
  return pour_can_pack_calibration_result(node->config.node_id, &r, frame) == POUR_OK;
}

uint8_t pour_can_node_end_tick(pour_can_node_t *node, const pour_control_output_t *out, uint32_t overruns,
                               pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX]) {
  (void)pour_can_node_watchdog(node, 1);
  uint8_t n = 0;
  if (pour_can_node_torque_frame(node, out, &tx[n]) == POUR_OK) {
    ++n;
  }
  if (node->ms_to_heartbeat == 0u) {
    n = (uint8_t)(n + pour_can_node_status_frames(node, out, overruns, &tx[n]));
    if (node->have_drive && pour_can_pack_drive_telemetry(node->config.node_id, &node->drive, &tx[n]) == POUR_OK) {
      ++n;
    }
    node->ms_to_heartbeat = node->config.heartbeat_period_ms;
  }
  --node->ms_to_heartbeat;
  if (pour_can_node_calibration_frame(node, out->mode, &tx[n])) {
    ++n;
  }
  return n;
}

void pour_can_node_set_drive(pour_can_node_t *node, const pour_can_drive_telemetry_t *drive) {
  node->drive = *drive;
  node->have_drive = true;
}

void pour_can_node_set_held(pour_can_node_t *node, bool held) { node->held = held; }

void pour_can_node_report_calibration(pour_can_node_t *node, const pour_can_calibration_result_t *result) {
  node->calibration = *result;
  node->calibration_report = true;
}

void pour_can_node_gate_calibration(pour_can_node_t *node, uint8_t answer) { node->calibration_gate = answer; }

bool pour_can_node_take_calibration_start(pour_can_node_t *node) {
  const bool start = node->calibration_start;
  node->calibration_start = false;
  return start;
}

void pour_can_node_set_calibration(pour_can_node_t *node, const pour_can_calibration_result_t *result) {
  node->calibration = *result;
}

bool pour_can_node_take_experiment(pour_can_node_t *node, uint8_t *kind) {
  if (!node->experiment_requested) {
    return false;
  }
  *kind = node->experiment_kind;
  node->experiment_requested = false;
  return true;
}

pour_status_t pour_can_node_experiment_ack(const pour_can_node_t *node, uint8_t kind, uint8_t answer,
                                           pour_can_frame_t *frame) {
  pour_can_param_ack_t ack = {.request = POUR_CAN_CMD_EXPERIMENT_START, .param_id = kind, .result = 0u};
  switch (answer) {
    case POUR_CONTROL_EXPERIMENT_ACCEPTED: ack.result = (uint8_t)POUR_PARAM_OK; break;
    case POUR_CONTROL_EXPERIMENT_REFUSED_RUNNING: ack.result = POUR_CAN_ACK_REFUSED_RUNNING; break;
    case POUR_CONTROL_EXPERIMENT_REFUSED_ESTOP: ack.result = POUR_CAN_ACK_REFUSED_ESTOP; break;
    case POUR_CONTROL_EXPERIMENT_REFUSED_FAULT: ack.result = POUR_CAN_ACK_REFUSED_FAULT; break;
    case POUR_CONTROL_EXPERIMENT_REFUSED_KIND: ack.result = (uint8_t)POUR_PARAM_OUT_OF_RANGE; break;
    default: return POUR_EINVAL; /* nothing was answered */
  }
  return pour_can_pack_param_ack(node->config.node_id, &ack, frame);
}
