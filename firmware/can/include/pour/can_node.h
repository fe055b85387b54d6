/* SPDX-License-Identifier: MIT */
/* The controller's side of the CAN protocol: received frames -> control input, control output -> frames,
 * plus the command watchdog and the heartbeat schedule. Pure: no I/O; the port moves the frames. The node
 * keeps no fault of its own: a tripped watchdog reaches the core as its link fault (POUR_FAULT_LINK), and
 * the core's output, e-stop and faults included, is what goes on the bus. */
#ifndef POUR_CAN_NODE_H
#define POUR_CAN_NODE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/can_codec.h"
#include "pour/commands.h"
#include "pour/control.h"
#include "pour/fixed.h"
#include "pour/sensors.h"

#define POUR_CAN_NODE_MAX_TX 5u /* frames one tick can produce: torque, heartbeat, identity, drive telemetry,
                                 * calibration result */

typedef struct {
  uint8_t node_id;              /* 0 .. 63 */
  uint16_t watchdog_ms;         /* >= 1: no valid sample or command for longer trips the watchdog [ms] */
  uint16_t heartbeat_period_ms; /* >= 1: a heartbeat and an identity frame every this many ticks [ms] */
  pour_can_identity_t identity; /* what the identity frame says (policy hash, tau_max, version, init) */
  bool can_calibrate;           /* the port measures: a CalibrationStart not refused is answered MEASURING and
                                   handed to it (pour_can_node_take_calibration_start) */
} pour_can_node_config_t;

/* Receive counters; they saturate at UINT32_MAX. */
typedef struct {
  uint32_t accepted;     /* well-formed frames of ours */
  uint32_t bad_id;       /* our node, unknown or send-only cmd */
  uint32_t bad_dlc;      /* wrong data length */
  uint32_t out_of_range; /* a signal outside its DBC range */
  uint32_t other_node;   /* other nodes' frames (ignored, not an error) */
  uint32_t param_busy;   /* a parameter request that came while the previous one waited for the port */
} pour_can_node_counters_t;

/* A parameter request (ParamRead, ParamWrite, ParamSave, Tare, Zero) waiting for the port, which answers it
 * with pour_can_params_handle (can_params.h). */
typedef struct {
  uint8_t cmd;      /* POUR_CAN_CMD_PARAM_READ, _PARAM_WRITE, _PARAM_SAVE, _TARE or _ZERO */
  uint8_t param_id; /* read, write */
  int32_t value;    /* write */
  uint8_t scales;   /* tare: POUR_CAN_TARE_* bits */
} pour_can_param_request_t;

typedef struct {
  pour_can_node_config_t config;
  bool have_seq;                /* a sample arrived since init */
  pour_sensors_t sensors;       /* latest sensor sample, seq extended to 32 bits */
  bool sensors_fresh;           /* arrived since the last tick */
  pour_commands_t commands;     /* Estop, ClearErrors, Stop and Reset since the last tick, in their order */
  bool param_pending;           /* param_request waits for the port */
  pour_can_param_request_t param_request;
  bool armed;                   /* watchdog runs once the first valid sample arrived */
  uint32_t ms_since_valid;
  uint16_t ms_to_heartbeat;
  uint8_t heartbeat_counter;
  pour_can_node_counters_t counters;
  bool calibration_requested;                /* a CalibrationStart arrived since the last tick */
  bool calibration_read;                     /* a CalibrationRead waits for its answer */
  bool calibration_start;                    /* one was accepted: the port has not taken it yet */
  bool calibration_report;                   /* the port's outcome waits to be sent */
  uint8_t calibration_gate;                  /* the port's interlock: POUR_CAN_CAL_MEASURING or a refusal */
  pour_can_calibration_result_t calibration; /* what the port says a start does and what is stored */
  bool experiment_requested;                 /* an ExperimentStart arrived and waits for the port */
  uint8_t experiment_kind;                   /* ... of this kind */
  bool have_drive;                           /* the port has a drive of its own: DriveTelemetry is sent */
  pour_can_drive_telemetry_t drive;          /* its latest state */
  bool held;                                 /* the core's pour_control_held, for the heartbeat's Held */
} pour_can_node_t;

/* Node 0, watchdog 50 ms (above the core's input timeout, so the core trips first), heartbeat 100 ms,
 * an identity of hash 0, tau_max 0 and this firmware's version. */
pour_can_node_config_t pour_can_node_default_config(void);

/* Validates config (POUR_EINVAL otherwise); no sample yet, heartbeat due on the first tick. */
pour_status_t pour_can_node_init(pour_can_node_t *node, const pour_can_node_config_t *config);

/* What the port answers a CalibrationStart with when it is not refused: status (POUR_CAN_CAL_*) and the
 * stored calibration. Until set: UNAVAILABLE and nothing stored (EMPTY). */
void pour_can_node_set_calibration(pour_can_node_t *node, const pour_can_calibration_result_t *result);

/* The drive's state for the next DriveTelemetry (a port with a drive of its own calls it every tick; from
 * the first call on, a DriveTelemetry frame follows every heartbeat). */
void pour_can_node_set_drive(pour_can_node_t *node, const pour_can_drive_telemetry_t *drive);

/* Whether the core holds the axis awaiting a Reset (pour_control_held), for the next heartbeat's Held: a port
 * calls it every tick before pour_can_node_end_tick (false until it does). */
void pour_can_node_set_held(pour_can_node_t *node, bool held);

/* The measurement's outcome (status POUR_CAN_CAL_*, the calibration stored), sent unasked as a
 * CalibrationResult at the end of a tick (after a pending request's answer, if any: one a tick). */
void pour_can_node_report_calibration(pour_can_node_t *node, const pour_can_calibration_result_t *result);

/* The port's interlock, each tick before end_tick: what a CalibrationStart that RUN and the e-stop do not
 * refuse is answered with (config.can_calibrate): POUR_CAN_CAL_MEASURING accepts it, any other status
 * refuses it with that reason. MEASURING until called. */
void pour_can_node_gate_calibration(pour_can_node_t *node, uint8_t answer);

/* Takes an accepted CalibrationStart (config.can_calibrate), once: true if one waits. */
bool pour_can_node_take_calibration_start(pour_can_node_t *node);

/* Feeds one received frame. Malformed frames are dropped and counted, never acted on. */
pour_can_rx_t pour_can_node_receive(pour_can_node_t *node, const pour_can_frame_t *frame);

/* A sample of the port's hardwired e-stop input, taken before the tick's frames are fed and again after
 * them: the e-stop is asserted while the line or the bus asserts it, and a ClearErrors counts only if both
 * were released when it arrived and stayed released until the tick. */
void pour_can_node_estop_line(pour_can_node_t *node, bool asserted);

/* Start of a 1 ms tick, once per tick: the control input from what arrived since the last tick (the
 * latest Sensors sample, as the sensors read it), the watchdog's state as in->link_fault, no drive fault. The frame's
 * 8-bit seq reaches the core extended to 32 bits by its forward distance (it wraps every 256 ms at 1 kHz;
 * a wrap is just the next sample). A Reset does not restart the count: the core, when it accepts the
 * Reset, takes the new run's first sample whatever its seq, and a refused Reset changes nothing here. */
void pour_can_node_begin_tick(pour_can_node_t *node, pour_control_input_t *in);

/* End of a tick: advances the watchdog by 1 ms, then writes the torque frame, when due the heartbeat and
 * the identity frame (and DriveTelemetry, once pour_can_node_set_drive was called), and after a
 * CalibrationStart its CalibrationResult into tx: refused in RUN (REFUSED_RUNNING) and in ESTOP
 * (REFUSED_ESTOP), else the port's gate if it measures (config.can_calibrate: MEASURING, or its
 * interlock's refusal; pour_can_node_gate_calibration), else the port's answer
 * (pour_can_node_set_calibration); or else a reported outcome; or else, after a CalibrationRead, the stored
 * calibration with Status STORED (UNAVAILABLE without config.can_calibrate: no calibration of its own), in
 * any mode, changing nothing. One CalibrationResult a tick: a read waits behind the others. overruns: the
 * port's missed deadlines.
 * Returns the count. */
uint8_t pour_can_node_end_tick(pour_can_node_t *node, const pour_control_output_t *out, uint32_t overruns,
                               pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX]);

/* The CalibrationResult end_tick sends, for a port that sends it itself (mode: the core's pour_mode_t of
 * the tick): the answer to a CalibrationStart since the last call (its refusal, MEASURING, or the port's
 * answer), else a reported outcome, else the answer to a CalibrationRead. Returns false if there is none. */
bool pour_can_node_calibration_frame(pour_can_node_t *node, uint8_t mode, pour_can_frame_t *frame);

/* Advances the command watchdog by elapsed_ms (end_tick does it by 1 each tick; a port without a tick of
 * its own, such as the Linux one, by wall-clock time). Returns whether it has tripped. */
bool pour_can_node_watchdog(pour_can_node_t *node, uint32_t elapsed_ms);

/* The frames end_tick is made of, for a port that schedules them itself (the Linux one, by wall clock). */
pour_status_t pour_can_node_torque_frame(const pour_can_node_t *node, const pour_control_output_t *out,
                                         pour_can_frame_t *frame);
/* Heartbeat (counter advanced; Refused = the core's refused Stops, Resets and clears plus the clears dropped
 * here, mod 16) then identity: 2 frames, or 0 if the output cannot be packed. */
uint8_t pour_can_node_status_frames(pour_can_node_t *node, const pour_control_output_t *out, uint32_t overruns,
                                    pour_can_frame_t tx[2]);

/* Takes the waiting parameter request, if any (one at a time: another that comes before is dropped and
 * counted as param_busy). */
bool pour_can_node_take_param_request(pour_can_node_t *node, pour_can_param_request_t *request);

/* Takes the waiting ExperimentStart, if any (the latest one): the port hands its kind to the core
 * (pour_control_experiment) before the tick's update. */
bool pour_can_node_take_experiment(pour_can_node_t *node, uint8_t *kind);

/* The ParamAck (Request = ExperimentStart, ParamId = kind) that answers it, from the core's answer
 * (pour_control_experiment_answer_t): OK when accepted, else the refusal's reason. */
pour_status_t pour_can_node_experiment_ack(const pour_can_node_t *node, uint8_t kind, uint8_t answer,
                                           pour_can_frame_t *frame);

/* Total of the dropped-frame counters (what the heartbeat's RxDropped carries, mod 2^16). */
uint32_t pour_can_node_dropped(const pour_can_node_t *node);

#endif /* POUR_CAN_NODE_H */
