/* SPDX-License-Identifier: MIT */
/* can_bridge's logic, no I/O: LCM messages <-> pour CAN frames (can/pour.dbc).
 *   POUR_SENSORS (pour_sensor_sample_t) -> Sensors        (the raw readings as they are: no conversion)
 *   POUR_COMMAND (pour_command_t)     -> Estop (+ Stop, ClearErrors, Reset)
 *   Torque frame                      -> POUR_TORQUE (pour_torque_t; seq, episode and utime restored)
 *   Heartbeat frame                   -> POUR_STATUS (pour_controller_status_t)
 *   Identity frame                    -> the torque scale and the policy hash of the POUR_TORQUE it makes
 * CAN carries 8 bits of seq (the controller extends them to its own count, whose low 16 bits its Torque
 * frames echo) and no episode or time stamp: the bridge remembers the last 256 samples it sent, by the low
 * 8 bits of seq, and answers torque frames only for those. The torque scale comes from the controller's
 * Identity frame, never from the bridge's own build or a default. */
#ifndef POUR_CAN_BRIDGE_H
#define POUR_CAN_BRIDGE_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/can_codec.h"
#include "pour_command_t.h"
#include "pour_controller_status_t.h"
#include "pour_sensor_sample_t.h"
#include "pour_torque_t.h"

#define POUR_BRIDGE_RING 256u /* samples remembered for matching answers: one per value of Sensors.Seq */

typedef struct {
  uint8_t node_id;     /* controller node id, 0 .. 63 */
  uint8_t n_actions;   /* pour_torque_t.n_actions, 2 .. 16 (CAN carries no probabilities: they stay 0) */
} pour_bridge_config_t;

typedef struct {
  int64_t seq;
  int64_t utime;
  int32_t episode;
  bool used;
} pour_bridge_sent_t;

typedef struct {
  int64_t states_sent;      /* sensor samples sent */
  int64_t states_refused;   /* POUR_SENSORS readings outside the Sensors frame's ranges: not sent */
  int64_t torques;          /* torque frames turned into POUR_TORQUE */
  int64_t torques_unmatched; /* torque frames answering no sample we sent (dropped) */
  int64_t heartbeats;
  int64_t identities;       /* Identity frames seen */
  int64_t frames_dropped;   /* malformed or unknown frames of the controller's node */
  int64_t commands;
} pour_bridge_counters_t;

typedef struct {
  pour_bridge_config_t config;
  pour_bridge_sent_t sent[POUR_BRIDGE_RING]; /* by the low 8 bits of seq */
  pour_bridge_counters_t counters;
  uint8_t mode;            /* from the latest heartbeat or torque frame */
  uint16_t faults;
  int64_t heartbeat_count; /* heartbeats seen, as POUR_STATUS.tick has nothing better over CAN */
  bool have_identity;      /* an Identity frame arrived: identity is the controller's */
  pour_can_identity_t identity;
} pour_bridge_t;

/* Defaults: node 0, 11 actions. */
pour_bridge_config_t pour_bridge_default_config(void);

/* POUR_EINVAL for a node id > 63 or n_actions outside 2 .. 16. */
pour_status_t pour_bridge_init(pour_bridge_t *b, const pour_bridge_config_t *config);

/* The Sensors frame of one POUR_SENSORS sample: returns 1, or 0 if a reading is outside what the frame
 * carries (an encoder count outside 0 .. 2^24 - 1, a scale outside ±32767 g): counted, and *why (if not
 * NULL) names the reading. */
int pour_bridge_from_sensors(pour_bridge_t *b, const pour_sensor_sample_t *msg, pour_can_frame_t frame[1],
                             const char **why);

/* Estop (always, as the level), then Stop, ClearErrors and Reset (those asked for): returns the count, 1..4. */
int pour_bridge_from_command(pour_bridge_t *b, const pour_command_t *msg, pour_can_frame_t frames[4]);

typedef enum {
  POUR_BRIDGE_NONE = 0,   /* not the controller's, or a frame the host itself sends: ignored */
  POUR_BRIDGE_TORQUE = 1, /* *torque filled: publish on POUR_TORQUE */
  POUR_BRIDGE_STATUS = 2, /* *status filled: publish on POUR_STATUS */
  POUR_BRIDGE_DROPPED = -1 /* the controller's, but malformed, or a torque that answers no sent sample */
} pour_bridge_out_t;

/* One frame from the bus. utime [µs] stamps the message published. Until the controller's Identity frame
 * has arrived, POUR_TORQUE carries torque NaN [N·m] (scale unknown) and weights_hash 0. */
pour_bridge_out_t pour_bridge_from_frame(pour_bridge_t *b, const pour_can_frame_t *frame, int64_t utime,
                                         pour_torque_t *torque, pour_controller_status_t *status);

#endif /* POUR_CAN_BRIDGE_H */
