/* SPDX-License-Identifier: MIT */
/* Parameter requests over CAN (ParamRead, ParamWrite, ParamSave, Tare, Zero -> ParamValue or ParamAck): the
 * one answer both ports give. Pure: the port supplies the core's state, and how a new set is put in force
 * and stored. */
#ifndef POUR_CAN_PARAMS_H
#define POUR_CAN_PARAMS_H

#include <stdbool.h>

#include "pour/can_codec.h"
#include "pour/can_node.h"
#include "pour/params.h"

typedef struct {
  bool writable;          /* the core takes a new configuration now (pour_params_writable) */
  bool have_sample;       /* a sensor sample has arrived */
  pour_sensors_t sample;  /* the latest one, raw (what tare and zero take) */
  /* Puts a candidate set in force; POUR_OK, or an error if the core refuses it (then nothing changed). */
  pour_status_t (*apply)(void *user, const pour_params_t *candidate);
  /* Stores the set; NULL: the controller has no storage (save is refused with POUR_PARAM_NO_STORAGE). */
  pour_status_t (*save)(void *user, const pour_params_t *params);
  void *user;
} pour_can_params_env_t;

/* Answers one request into *reply (ParamValue for an accepted read or write, else ParamAck with the result);
 * *params changes only when a write, tare or zero is accepted. Order of the checks: unknown id, range,
 * writable (BUSY), the set's rules, the core's; a save: storage (NO_STORAGE), writable (BUSY). Returns the
 * result. */
pour_param_result_t pour_can_params_handle(uint8_t node_id, const pour_can_param_request_t *request,
                                           pour_params_t *params, const pour_can_params_env_t *env,
                                           pour_can_frame_t *reply);

#endif /* POUR_CAN_PARAMS_H */
