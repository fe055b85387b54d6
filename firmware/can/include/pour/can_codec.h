/* SPDX-License-Identifier: MIT */
/* The pour CAN protocol (can/pour.dbc): frame ids, message structs, pack and unpack. Pure: no I/O.
 * Classic CAN, 11-bit ids, id = (node_id << 5) | cmd; all signals little-endian (DBC "@1"). */
#ifndef POUR_CAN_CODEC_H
#define POUR_CAN_CODEC_H

#include <stdint.h>

#include "pour/faults.h"
#include "pour/fixed.h"

#define POUR_CAN_NODE_ID_MAX 63u /* node ids 0 .. 63 (6 bits) */
#define POUR_CAN_CMD_MASK 0x1Fu  /* cmd ids 0 .. 31 (5 bits) */
#define POUR_CAN_NODE_SHIFT 5u
#define POUR_CAN_NODE_MASK 0x7E0u /* acceptance mask that selects one node's ids */
#define POUR_CAN_STD_ID_MAX 0x7FFu

/* Command ids (the DBC's frame ids for node 0). */
#define POUR_CAN_CMD_HEARTBEAT 0x01u    /* controller -> host, every heartbeat period */
#define POUR_CAN_CMD_ESTOP 0x02u        /* host -> controller */
#define POUR_CAN_CMD_STOP 0x03u         /* host -> controller: end the run */
#define POUR_CAN_CMD_IDENTITY 0x04u     /* controller -> host, with every heartbeat: policy, scale, version */
#define POUR_CAN_CMD_SENSORS 0x10u      /* host -> controller: one raw sensor sample (encoder, scales) */
#define POUR_CAN_CMD_TORQUE 0x12u       /* controller -> host, one per control tick */
#define POUR_CAN_CMD_CLEAR_ERRORS 0x18u /* host -> controller */
#define POUR_CAN_CMD_RESET 0x19u        /* host -> controller: start a new run (refused while running) */

/* Data length of each message [bytes]; a frame with another DLC is malformed. */
#define POUR_CAN_DLC_HEARTBEAT 8u
#define POUR_CAN_DLC_ESTOP 1u
#define POUR_CAN_DLC_STOP 0u
#define POUR_CAN_DLC_IDENTITY 8u
#define POUR_CAN_DLC_SENSORS 8u
#define POUR_CAN_DLC_TORQUE 7u
#define POUR_CAN_DLC_CLEAR_ERRORS 0u
#define POUR_CAN_DLC_RESET 0u

/* Signal ranges, as the DBC's [min|max] in raw units; a value outside is out of range. */
#define POUR_CAN_ENCODER_MAX 0xFFFFFFu /* 24-bit count field: encoders of up to 24 bits; the core's estimator
                                         * refuses a count >= 2^encoder_bits (BAD_INPUT) */
#define POUR_CAN_SCALE_MAX_G 32767     /* |scale| <= 32.767 kg [g]; -32768 is the load cell amplifier's
                                         * overload code, out of range */
#define POUR_CAN_MODE_MAX (POUR_MODE_COUNT - 1u) /* pour_mode_t */
#define POUR_CAN_ACTION_MAX 15u
#define POUR_CAN_LIMITS_MAX 63u /* POUR_LIMIT_* bits 0..5, the motion envelope's speed and acceleration included */
#define POUR_CAN_INIT_STATUS_MIN (-128) /* Identity.InitStatus: a pour_status_t, 0 = OK */

/* The CAN node's command watchdog latches in the core as its link fault. */
#define POUR_CAN_FAULT_WATCHDOG POUR_FAULT_LINK

/* A classic CAN data frame with an 11-bit id. */
typedef struct {
  uint16_t id;     /* 0 .. 0x7FF */
  uint8_t dlc;     /* 0 .. 8 */
  uint8_t data[8]; /* bytes past dlc are zero in packed frames and ignored on unpack */
} pour_can_frame_t;

/* One raw sensor sample (pour_sensors_t on the wire): the encoder and the scales as the sensors read them,
 * no conversion, so a sample over CAN reaches the core with the bits it has in-process. */
typedef struct {
  uint8_t seq_low;          /* low 8 bits of the sample counter; the node extends it to 32 bits */
  uint32_t encoder;         /* raw single-turn count, 0 .. POUR_CAN_ENCODER_MAX */
  int16_t scale_rotating_g; /* [g], |.| <= POUR_CAN_SCALE_MAX_G */
  int16_t scale_target_g;   /* [g], |.| <= POUR_CAN_SCALE_MAX_G */
} pour_can_sensors_t;

typedef struct {
  uint16_t seq;   /* seq of the latest complete state */
  q15_t torque;   /* fraction of tau_max, Q15 */
  uint8_t action; /* 0 .. 15 */
  uint8_t mode;   /* pour_mode_t, 0 .. 3 */
  uint8_t limits; /* POUR_LIMIT_* bits, 0 .. 63 */
} pour_can_torque_t;

typedef struct {
  uint8_t mode;        /* pour_mode_t, 0 .. 3 */
  uint16_t faults;     /* POUR_FAULT_* | POUR_CAN_FAULT_*; only the bits the DBC names are carried */
  uint16_t rx_dropped; /* malformed frames dropped, wraps */
  uint16_t overruns;   /* missed control deadlines, wraps */
  uint8_t counter;     /* +1 per heartbeat, wraps */
} pour_can_heartbeat_t;

typedef struct {
  uint8_t assert_estop; /* 1 assert, 0 release */
} pour_can_estop_t;

/* Who is on the bus: the policy it runs and the scale of its Torque frames. */
typedef struct {
  uint32_t weights_hash;   /* content hash of the compiled-in weights.h (FNV-1a 32) */
  uint16_t tau_max_cnm;    /* tau_max, the torque of Q15 1.0 in the Torque frame [0.01 N·m] */
  uint8_t fw_version;      /* POUR_FIRMWARE_VERSION */
  int8_t init_status;      /* pour_status_t of the controller's start-up (0 = OK, else it never runs) */
} pour_can_identity_t;

/* The fault bits the heartbeat carries: every POUR_FAULT_* of the core, the link (watchdog) fault included. */
#define POUR_CAN_HEARTBEAT_FAULT_MASK POUR_FAULT_ALL

/* Decoded frame classes and the reasons a frame is not accepted. */
typedef enum {
  POUR_CAN_RX_OK = 0,          /* a well-formed frame of ours */
  POUR_CAN_RX_OTHER_NODE = 1,  /* another node's id: not ours, silently ignored */
  POUR_CAN_RX_BAD_ID = -1,     /* our node, but no such cmd (or a cmd we only send) */
  POUR_CAN_RX_BAD_DLC = -2,    /* known cmd with the wrong data length */
  POUR_CAN_RX_OUT_OF_RANGE = -3 /* a signal outside its DBC range */
} pour_can_rx_t;

/* id of cmd for node_id (both masked to their field widths). */
static inline uint16_t pour_can_id(uint8_t node_id, uint8_t cmd) {
  return (uint16_t)(((uint32_t)(node_id & POUR_CAN_NODE_ID_MAX) << POUR_CAN_NODE_SHIFT) |
                    (cmd & POUR_CAN_CMD_MASK));
}

/* Pack functions: POUR_EINVAL for a null pointer, a node id > 63 or a field outside its DBC range
 * (the frame is then left untouched). */
pour_status_t pour_can_pack_sensors(uint8_t node_id, const pour_can_sensors_t *msg, pour_can_frame_t *frame);
pour_status_t pour_can_pack_torque(uint8_t node_id, const pour_can_torque_t *msg, pour_can_frame_t *frame);
pour_status_t pour_can_pack_heartbeat(uint8_t node_id, const pour_can_heartbeat_t *msg,
                                      pour_can_frame_t *frame);
pour_status_t pour_can_pack_estop(uint8_t node_id, const pour_can_estop_t *msg, pour_can_frame_t *frame);
pour_status_t pour_can_pack_identity(uint8_t node_id, const pour_can_identity_t *msg, pour_can_frame_t *frame);
/* The commands without signals: POUR_CAN_CMD_CLEAR_ERRORS, _STOP and _RESET (POUR_EINVAL for another cmd). */
pour_status_t pour_can_pack_command(uint8_t node_id, uint8_t cmd, pour_can_frame_t *frame);

/* Unpack functions check the id's cmd, the DLC and every range; msg is written only on POUR_CAN_RX_OK.
 * The node id of the frame is not checked here (pour_can_classify does that). */
pour_can_rx_t pour_can_unpack_sensors(const pour_can_frame_t *frame, pour_can_sensors_t *msg);
pour_can_rx_t pour_can_unpack_torque(const pour_can_frame_t *frame, pour_can_torque_t *msg);
pour_can_rx_t pour_can_unpack_heartbeat(const pour_can_frame_t *frame, pour_can_heartbeat_t *msg);
pour_can_rx_t pour_can_unpack_estop(const pour_can_frame_t *frame, pour_can_estop_t *msg);
pour_can_rx_t pour_can_unpack_identity(const pour_can_frame_t *frame, pour_can_identity_t *msg);
/* The commands without signals: checks the id's cmd (as given) and the DLC. */
pour_can_rx_t pour_can_unpack_command(const pour_can_frame_t *frame, uint8_t cmd);

/* Classifies a frame for a receiver: POUR_CAN_RX_OTHER_NODE, or for node_id's frames whether cmd is one
 * of the accepted ones (accept_mask bit cmd set) with the expected DLC; *cmd gets the cmd id. */
pour_can_rx_t pour_can_classify(const pour_can_frame_t *frame, uint8_t node_id, uint32_t accept_mask,
                                uint8_t *cmd);

/* Expected DLC of a cmd, or -1 for a cmd the protocol does not define. */
int pour_can_dlc_of(uint8_t cmd);

#endif /* POUR_CAN_CODEC_H */
