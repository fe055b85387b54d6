/* SPDX-License-Identifier: MIT */
#include "bridge.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "pour/control.h"

pour_bridge_config_t pour_bridge_default_config(void) {
  pour_bridge_config_t c;
  c.node_id = 0;
  c.n_actions = 11;
  return c;
}

pour_status_t pour_bridge_init(pour_bridge_t *b, const pour_bridge_config_t *config) {
  if (b == NULL || config == NULL || config->node_id > POUR_CAN_NODE_ID_MAX ||
      config->n_actions < 2u || config->n_actions > 16u) {
    return POUR_EINVAL;
  }
  memset(b, 0, sizeof *b);
  b->config = *config;
  return POUR_OK;
}

int pour_bridge_from_sensors(pour_bridge_t *b, const pour_sensor_sample_t *msg, pour_can_frame_t frame[1],
                             const char **why) {
  /* The readings cross as they are, so the controller's estimator gets the bits the in-process simulator
   * hands its core; only what the frame cannot hold is refused (the frame would carry another value). */
  const char *bad = NULL;
  if (msg->encoder < 0 || (uint32_t)msg->encoder > POUR_CAN_ENCODER_MAX) {
    bad = "encoder count outside 0 .. 2^24 - 1";
  } else if (msg->scale_rotating_g < -POUR_CAN_SCALE_MAX_G || msg->scale_rotating_g > POUR_CAN_SCALE_MAX_G) {
    bad = "scale_rotating_g outside -32767 .. 32767 g";
  } else if (msg->scale_target_g < -POUR_CAN_SCALE_MAX_G || msg->scale_target_g > POUR_CAN_SCALE_MAX_G) {
    bad = "scale_target_g outside -32767 .. 32767 g";
  }
  const uint8_t seq8 = (uint8_t)((uint64_t)msg->seq & 0xFFu);
  const pour_can_sensors_t m = {seq8, (uint32_t)msg->encoder, (int16_t)msg->scale_rotating_g,
                                (int16_t)msg->scale_target_g};
  if (bad != NULL || pour_can_pack_sensors(b->config.node_id, &m, &frame[0]) != POUR_OK) {
    if (why != NULL) {
      *why = bad != NULL ? bad : "not packable";
    }
    b->counters.states_refused++;
    return 0;
  }
  pour_bridge_sent_t *slot = &b->sent[seq8];
  slot->seq = msg->seq;
  slot->utime = msg->utime;
  slot->episode = msg->episode;
  slot->used = true;
  b->counters.states_sent++;
  return 1;
}

int pour_bridge_from_command(pour_bridge_t *b, const pour_command_t *msg, pour_can_frame_t frames[4]) {
  const pour_can_estop_t e = {(uint8_t)(msg->estop ? 1u : 0u)};
  int n = 0;
  if (pour_can_pack_estop(b->config.node_id, &e, &frames[n]) == POUR_OK) {
    n++;
  }
  /* The core acts on them in this order within one tick (stop ends the run, then reset may start one). */
  const struct {
    int8_t asked;
    uint8_t cmd;
  } one_shots[3] = {{msg->stop, POUR_CAN_CMD_STOP},
                    {msg->clear_faults, POUR_CAN_CMD_CLEAR_ERRORS},
                    {msg->reset, POUR_CAN_CMD_RESET}};
  for (unsigned i = 0; i < 3u; ++i) {
    if (one_shots[i].asked && pour_can_pack_command(b->config.node_id, one_shots[i].cmd, &frames[n]) == POUR_OK) {
      n++;
    }
  }
  b->counters.commands++;
  return n;
}

static pour_bridge_out_t torque_of(pour_bridge_t *b, const pour_can_frame_t *frame, int64_t utime,
                                   pour_torque_t *out) {
  pour_can_torque_t t;
  if (pour_can_unpack_torque(frame, &t) != POUR_CAN_RX_OK) {
    b->counters.frames_dropped++;
    return POUR_BRIDGE_DROPPED;
  }
  /* The controller counts from the first Sensors.Seq it saw (8 bits), so only the low 8 bits of its echo are
   * the host's: they pick the latest sample sent with them, whatever the controller's count started at. */
  const pour_bridge_sent_t *slot = &b->sent[t.seq & 0xFFu];
  if (!slot->used) {
    b->counters.torques_unmatched++;
    return POUR_BRIDGE_DROPPED;
  }
  memset(out, 0, sizeof *out);
  out->utime = utime;
  out->seq = slot->seq;
  out->episode = slot->episode;
  out->state_utime = slot->utime;
  out->torque_q15 = t.torque;
  out->torque = b->have_identity ? (double)t.torque / 32768.0 * (double)b->identity.tau_max_cnm * 1e-2 : (double)NAN;
  out->weights_hash = b->have_identity ? (int32_t)b->identity.weights_hash : 0;
  out->action = (int8_t)t.action;
  out->mode = (int8_t)t.mode;
  out->faults = (int16_t)b->faults; /* the torque frame has no fault bits: the latest heartbeat's */
  out->n_actions = (int8_t)b->config.n_actions;
  b->mode = t.mode;
  b->counters.torques++;
  return POUR_BRIDGE_TORQUE;
}

static pour_bridge_out_t status_of(pour_bridge_t *b, const pour_can_frame_t *frame, int64_t utime,
                                   pour_controller_status_t *out) {
  pour_can_heartbeat_t hb;
  if (pour_can_unpack_heartbeat(frame, &hb) != POUR_CAN_RX_OK) {
    b->counters.frames_dropped++;
    return POUR_BRIDGE_DROPPED;
  }
  b->mode = hb.mode;
  b->faults = hb.faults;
  b->heartbeat_count++;
  b->counters.heartbeats++;
  memset(out, 0, sizeof *out);
  out->utime = utime;
  out->tick = b->heartbeat_count;
  out->mode = (int8_t)hb.mode;
  out->faults = (int16_t)hb.faults;
  out->weights_hash = b->have_identity ? (int32_t)b->identity.weights_hash : 0;
  out->overruns = hb.overruns;
  out->messages_dropped = hb.rx_dropped;
  /* Step time and lateness are not carried over CAN: they stay 0 (the fields' documented floor). */
  out->states_received = b->counters.states_sent;
  return POUR_BRIDGE_STATUS;
}

static pour_bridge_out_t identity_of(pour_bridge_t *b, const pour_can_frame_t *frame) {
  pour_can_identity_t id;
  if (pour_can_unpack_identity(frame, &id) != POUR_CAN_RX_OK) {
    b->counters.frames_dropped++;
    return POUR_BRIDGE_DROPPED;
  }
  b->identity = id;
  b->have_identity = true;
  b->counters.identities++;
  return POUR_BRIDGE_NONE;
}

pour_bridge_out_t pour_bridge_from_frame(pour_bridge_t *b, const pour_can_frame_t *frame, int64_t utime,
                                         pour_torque_t *torque, pour_controller_status_t *status) {
  const uint32_t accept =
      (1u << POUR_CAN_CMD_TORQUE) | (1u << POUR_CAN_CMD_HEARTBEAT) | (1u << POUR_CAN_CMD_IDENTITY);
  uint8_t cmd = 0;
  const pour_can_rx_t rc = pour_can_classify(frame, b->config.node_id, accept, &cmd);
  if (rc == POUR_CAN_RX_OTHER_NODE) {
    return POUR_BRIDGE_NONE;
  }
  if (rc == POUR_CAN_RX_BAD_ID && pour_can_dlc_of(cmd) >= 0) {
    return POUR_BRIDGE_NONE; /* a host-to-controller frame (ours, or another host's) */
  }
  if (rc != POUR_CAN_RX_OK) {
    b->counters.frames_dropped++;
    return POUR_BRIDGE_DROPPED;
  }
  if (cmd == POUR_CAN_CMD_IDENTITY) {
    return identity_of(b, frame);
  }
  return cmd == POUR_CAN_CMD_TORQUE ? torque_of(b, frame, utime, torque) : status_of(b, frame, utime, status);
}
