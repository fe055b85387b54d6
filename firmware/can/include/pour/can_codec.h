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
#define POUR_CAN_CMD_CALIBRATION_START 0x05u  /* host -> controller: calibrate the drive */
#define POUR_CAN_CMD_CALIBRATION_RESULT 0x06u /* controller -> host: the answer, and what is stored */
#define POUR_CAN_CMD_DRIVE_TELEMETRY 0x07u    /* controller -> host, with every heartbeat: id, iq, vbus, faults */
#define POUR_CAN_CMD_PARAM_READ 0x08u   /* host -> controller: read one parameter (pour/params.h) */
#define POUR_CAN_CMD_PARAM_VALUE 0x09u  /* controller -> host: a parameter's value (answers read and write) */
#define POUR_CAN_CMD_PARAM_WRITE 0x0Au  /* host -> controller: set one parameter (IDLE or FAULT only) */
#define POUR_CAN_CMD_PARAM_SAVE 0x0Bu   /* host -> controller: store all parameters */
#define POUR_CAN_CMD_PARAM_ACK 0x0Cu    /* controller -> host: the result of a parameter request */
#define POUR_CAN_CMD_TARE 0x0Du         /* host -> controller: tare the scales at their latest reading */
#define POUR_CAN_CMD_ZERO 0x0Eu         /* host -> controller: the encoder's latest count becomes upright */
#define POUR_CAN_CMD_EXPERIMENT_START 0x0Fu /* host -> controller: run an identification experiment */
#define POUR_CAN_CMD_SENSORS 0x10u      /* host -> controller: one raw sensor sample (encoder, scales) */
#define POUR_CAN_CMD_TORQUE 0x12u       /* controller -> host, one per control tick */
#define POUR_CAN_CMD_CLEAR_ERRORS 0x18u /* host -> controller */
#define POUR_CAN_CMD_RESET 0x19u        /* host -> controller: start a new run (refused while running) */
#define POUR_CAN_CMD_CALIBRATION_READ 0x1Au /* host -> controller: send the stored calibration (no motion) */

/* Data length of each message [bytes]; a frame with another DLC is malformed. */
#define POUR_CAN_DLC_HEARTBEAT 8u
#define POUR_CAN_DLC_ESTOP 1u
#define POUR_CAN_DLC_STOP 0u
#define POUR_CAN_DLC_IDENTITY 8u
#define POUR_CAN_DLC_CALIBRATION_START 0u
#define POUR_CAN_DLC_CALIBRATION_RESULT 8u
#define POUR_CAN_DLC_DRIVE_TELEMETRY 8u
#define POUR_CAN_DLC_PARAM_READ 1u
#define POUR_CAN_DLC_PARAM_VALUE 5u
#define POUR_CAN_DLC_PARAM_WRITE 5u
#define POUR_CAN_DLC_PARAM_SAVE 0u
#define POUR_CAN_DLC_PARAM_ACK 3u
#define POUR_CAN_DLC_TARE 1u
#define POUR_CAN_DLC_ZERO 0u
#define POUR_CAN_DLC_EXPERIMENT_START 1u
#define POUR_CAN_DLC_SENSORS 8u
#define POUR_CAN_DLC_TORQUE 7u
#define POUR_CAN_DLC_CLEAR_ERRORS 0u
#define POUR_CAN_DLC_RESET 0u
#define POUR_CAN_DLC_CALIBRATION_READ 0u

/* Signal ranges, as the DBC's [min|max] in raw units; a value outside is out of range. */
#define POUR_CAN_ENCODER_MAX 0xFFFFFFu /* 24-bit count field: encoders of up to 24 bits; the core's estimator
                                         * refuses a count >= 2^encoder_bits (BAD_INPUT) */
#define POUR_CAN_SCALE_MAX_G 32767     /* |scale| <= 32.767 kg [g]; -32768 is the load cell amplifier's
                                         * overload code, out of range */
#define POUR_CAN_MODE_MAX (POUR_MODE_COUNT - 1u) /* pour_mode_t */
#define POUR_CAN_REFUSED_MAX 0x0Fu                /* Heartbeat.Refused: a count mod 16 */
#define POUR_CAN_ACTION_MAX 15u
#define POUR_CAN_LIMITS_MAX 63u /* POUR_LIMIT_* bits 0..5, the motion envelope's speed and acceleration included */
#define POUR_CAN_INIT_STATUS_MIN (-128) /* Identity.InitStatus: a pour_status_t, 0 = OK */
#define POUR_CAN_POLE_PAIRS_MAX 32u
#define POUR_CAN_CURRENT_MAX 32767 /* |Id|, |Iq| [2 mA]; -32768 is out of range */
#define POUR_CAN_DRIVE_FAULT_MASK 0x07FFu /* the 11 bits of pour/drive_faults.h, in their order */
#define POUR_CAN_CRYSTAL_MAX 12u /* DriveTelemetry.Crystal [4 MHz]: 4 .. 48 MHz; 0 = no crystal, HSI16 */

/* CalibrationResult.Status: 0 .. 5 the stored block's state (as calibration_store.h's pour_cal_status_t),
 * then the refusals of a CalibrationStart, each with its reason, then the measurement's progress and why it
 * stopped (the drive's pour_motor_cal_status_t, pour/motor_cal.h). */
#define POUR_CAN_CAL_OK 0u
#define POUR_CAN_CAL_EMPTY 1u
#define POUR_CAN_CAL_CORRUPT 2u
#define POUR_CAN_CAL_OLD_VERSION 3u
#define POUR_CAN_CAL_OUT_OF_RANGE 4u
#define POUR_CAN_CAL_WRITE_FAILED 5u
#define POUR_CAN_CAL_REFUSED_RUNNING 6u /* asked for in RUN: Stop first */
#define POUR_CAN_CAL_REFUSED_ESTOP 7u   /* asked for while the e-stop is asserted */
#define POUR_CAN_CAL_UNAVAILABLE 8u     /* this controller cannot measure (no drive of its own) */
#define POUR_CAN_CAL_MEASURING 9u       /* started: the outcome follows, unasked, when it ends */
#define POUR_CAN_CAL_BAD_RESISTANCE 10u /* R out of range, or unequal on the two axes (an open phase) */
#define POUR_CAN_CAL_BAD_INDUCTANCE 11u /* L out of range */
#define POUR_CAN_CAL_NO_ENCODER 12u     /* the motor encoder did not count over an electrical turn */
#define POUR_CAN_CAL_BAD_POLE_PAIRS 13u /* the counts of an electrical turn fit no pole-pair count 1 .. 32 */
#define POUR_CAN_CAL_MOTION_RANGE 14u   /* the output moved beyond the sequence's range: stopped there */
#define POUR_CAN_CAL_ABORTED 15u        /* a fault, the e-stop or a stop ended it, or a latched fault refused it */
/* The interlock of the brake's release (calibration_flow.h): the bucket must be upright and empty. */
#define POUR_CAN_CAL_REFUSED_NOT_UPRIGHT 16u /* the output is more than 5° from upright */
#define POUR_CAN_CAL_REFUSED_NOT_EMPTY 17u   /* the rotating scale reads more than 200 g (or below -200 g) */
#define POUR_CAN_CAL_REFUSED_NO_SENSORS 18u  /* no sensor sample within 20 ms: no data is not "empty" */
/* The answer to a CalibrationRead: the frame carries the stored block (Stored says its state), not a new
 * measurement; a controller without a calibration of its own answers UNAVAILABLE instead. */
#define POUR_CAN_CAL_STORED 19u
#define POUR_CAN_CAL_STATUS_MAX 19u
#define POUR_CAN_CAL_STORED_MAX 5u
#define POUR_CAN_PARAM_RESULT_MAX 9u    /* ParamAck.Result: a pour_param_result_t, or an ExperimentStart's refusal */
/* ParamAck.Result for an ExperimentStart (beyond pour_param_result_t; OK: accepted, OUT_OF_RANGE: a kind
 * that does not run). */
#define POUR_CAN_ACK_REFUSED_RUNNING 7u /* asked for in RUN: Stop first */
#define POUR_CAN_ACK_REFUSED_ESTOP 8u   /* asked for while the e-stop is asserted */
#define POUR_CAN_ACK_REFUSED_FAULT 9u   /* asked for in FAULT: clear first */
#define POUR_CAN_EXPERIMENT_KIND_MIN 1u /* ExperimentStart.Kind: pour_experiment_kind_t that run */
#define POUR_CAN_EXPERIMENT_KIND_MAX 2u
#define POUR_CAN_TARE_ROTATING 1u       /* Tare.Scales bits */
#define POUR_CAN_TARE_TARGET 2u

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
  uint8_t mode;        /* pour_mode_t, 0 .. 3 (bits 0..3) */
  uint16_t faults;     /* POUR_FAULT_* | POUR_CAN_FAULT_*; only the bits the DBC names are carried */
  uint16_t rx_dropped; /* malformed frames dropped, wraps */
  uint16_t overruns;   /* missed control deadlines, wraps */
  uint8_t counter;     /* +1 per heartbeat, wraps */
  uint8_t refused;     /* commands refused or dropped (Stop, Reset, ClearErrors), mod 16 (bits 4..7) */
  uint8_t held;        /* 1: no run armed (after a boot of the board or a Stop; in FAULT, a clear leaves it so):
                        * RUN waits for a Reset (bit 23) */
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

/* The answer to a CalibrationStart, and the calibration stored in flash, read back. */
typedef struct {
  uint8_t status;            /* POUR_CAN_CAL_*, 0 .. POUR_CAN_CAL_STATUS_MAX */
  uint8_t stored;            /* the stored block's state, 0 .. POUR_CAN_CAL_STORED_MAX */
  uint8_t encoder_reversed;  /* 0, 1 */
  uint8_t pole_pairs;        /* 0 (none) .. POUR_CAN_POLE_PAIRS_MAX */
  uint16_t resistance_mohm;  /* phase resistance [mΩ] */
  uint16_t inductance_uh;    /* phase inductance [µH] */
  uint8_t electrical_offset; /* electrical angle at encoder count 0, 256 = 2π */
} pour_can_calibration_result_t;

/* The drive's state with every heartbeat. */
typedef struct {
  int16_t id_2ma;        /* d current [2 mA], |.| <= POUR_CAN_CURRENT_MAX */
  int16_t iq_2ma;        /* q current [2 mA], |.| <= POUR_CAN_CURRENT_MAX */
  uint16_t vbus_mv;      /* bus voltage [mV] */
  uint16_t drive_faults; /* POUR_DRIVE_FAULT_* (pour/drive_faults.h); only POUR_CAN_DRIVE_FAULT_MASK is carried */
  uint8_t crystal_4mhz;  /* the crystal the core clock runs from [4 MHz], <= POUR_CAN_CRYSTAL_MAX; 0: HSI16 */
} pour_can_drive_telemetry_t;
/* ParamRead: which parameter. */
typedef struct {
  uint8_t param_id; /* pour_param_id_t (an unknown id is the controller's to refuse, not malformed) */
} pour_can_param_read_t;

/* ParamValue and ParamWrite: a parameter and its value in the parameter's unit (pour/params.h). */
typedef struct {
  uint8_t param_id;
  int32_t value;
} pour_can_param_t;

/* ParamAck: what became of a request. */
typedef struct {
  uint8_t request;  /* cmd id of the request answered, 0 .. 31 */
  uint8_t param_id; /* its parameter (0 for save, tare and zero) */
  uint8_t result;   /* pour_param_result_t, 0 (ok) .. POUR_CAN_PARAM_RESULT_MAX */
} pour_can_param_ack_t;

typedef struct {
  uint8_t scales; /* POUR_CAN_TARE_* bits, 1 .. 3 */
} pour_can_tare_t;

/* ExperimentStart: which identification experiment (pour/experiment.h). */
typedef struct {
  uint8_t kind; /* pour_experiment_kind_t, POUR_CAN_EXPERIMENT_KIND_MIN .. _MAX */
} pour_can_experiment_start_t;

/* The fault bits the heartbeat carries: every POUR_FAULT_* of the core, the link (watchdog) fault included. */
#define POUR_CAN_HEARTBEAT_FAULT_MASK POUR_FAULT_ALL

/* Decoded frame classes and the reasons a frame is not accepted. */
typedef enum {
  POUR_CAN_RX_OK = 0,          /* a well-formed frame of ours */
  POUR_CAN_RX_OTHER_NODE = 1,  /* another node's id: not ours, silently ignored */
  POUR_CAN_RX_BAD_ID = -1,     /* our node, but no such cmd (or a cmd we only send) */
  POUR_CAN_RX_BAD_DLC = -2,    /* known cmd with the wrong data length */
  POUR_CAN_RX_OUT_OF_RANGE = -3, /* a signal outside its DBC range */
  POUR_CAN_RX_BUSY = -4          /* a parameter request while the previous one still waits (pour_can_node) */
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
pour_status_t pour_can_pack_calibration_result(uint8_t node_id, const pour_can_calibration_result_t *msg,
                                               pour_can_frame_t *frame);
pour_status_t pour_can_pack_drive_telemetry(uint8_t node_id, const pour_can_drive_telemetry_t *msg,
                                            pour_can_frame_t *frame);
pour_status_t pour_can_pack_param_read(uint8_t node_id, const pour_can_param_read_t *msg, pour_can_frame_t *frame);
/* cmd: POUR_CAN_CMD_PARAM_VALUE or _PARAM_WRITE (one layout). */
pour_status_t pour_can_pack_param(uint8_t node_id, uint8_t cmd, const pour_can_param_t *msg, pour_can_frame_t *frame);
pour_status_t pour_can_pack_param_ack(uint8_t node_id, const pour_can_param_ack_t *msg, pour_can_frame_t *frame);
pour_status_t pour_can_pack_tare(uint8_t node_id, const pour_can_tare_t *msg, pour_can_frame_t *frame);
pour_status_t pour_can_pack_experiment_start(uint8_t node_id, const pour_can_experiment_start_t *msg,
                                             pour_can_frame_t *frame);
/* The commands without signals: POUR_CAN_CMD_CLEAR_ERRORS, _STOP, _RESET, _CALIBRATION_START, _PARAM_SAVE,
 * _ZERO and _CALIBRATION_READ (POUR_EINVAL
 * for another cmd). */
pour_status_t pour_can_pack_command(uint8_t node_id, uint8_t cmd, pour_can_frame_t *frame);

/* Unpack functions check the id's cmd, the DLC and every range; msg is written only on POUR_CAN_RX_OK.
 * The node id of the frame is not checked here (pour_can_classify does that). */
pour_can_rx_t pour_can_unpack_sensors(const pour_can_frame_t *frame, pour_can_sensors_t *msg);
pour_can_rx_t pour_can_unpack_torque(const pour_can_frame_t *frame, pour_can_torque_t *msg);
pour_can_rx_t pour_can_unpack_heartbeat(const pour_can_frame_t *frame, pour_can_heartbeat_t *msg);
pour_can_rx_t pour_can_unpack_estop(const pour_can_frame_t *frame, pour_can_estop_t *msg);
pour_can_rx_t pour_can_unpack_identity(const pour_can_frame_t *frame, pour_can_identity_t *msg);
pour_can_rx_t pour_can_unpack_calibration_result(const pour_can_frame_t *frame, pour_can_calibration_result_t *msg);
pour_can_rx_t pour_can_unpack_drive_telemetry(const pour_can_frame_t *frame, pour_can_drive_telemetry_t *msg);
pour_can_rx_t pour_can_unpack_param_read(const pour_can_frame_t *frame, pour_can_param_read_t *msg);
pour_can_rx_t pour_can_unpack_param(const pour_can_frame_t *frame, uint8_t cmd, pour_can_param_t *msg);
pour_can_rx_t pour_can_unpack_param_ack(const pour_can_frame_t *frame, pour_can_param_ack_t *msg);
pour_can_rx_t pour_can_unpack_tare(const pour_can_frame_t *frame, pour_can_tare_t *msg);
pour_can_rx_t pour_can_unpack_experiment_start(const pour_can_frame_t *frame, pour_can_experiment_start_t *msg);
/* The commands without signals: checks the id's cmd (as given) and the DLC. */
pour_can_rx_t pour_can_unpack_command(const pour_can_frame_t *frame, uint8_t cmd);

/* Classifies a frame for a receiver: POUR_CAN_RX_OTHER_NODE, or for node_id's frames whether cmd is one
 * of the accepted ones (accept_mask bit cmd set) with the expected DLC; *cmd gets the cmd id. */
pour_can_rx_t pour_can_classify(const pour_can_frame_t *frame, uint8_t node_id, uint32_t accept_mask,
                                uint8_t *cmd);

/* Expected DLC of a cmd, or -1 for a cmd the protocol does not define. */
int pour_can_dlc_of(uint8_t cmd);

#endif /* POUR_CAN_CODEC_H */
