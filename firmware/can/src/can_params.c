/* SPDX-License-Identifier: MIT */
#include "pour/can_params.h"

#include <stddef.h>

static pour_param_result_t reply_value(uint8_t node_id, const pour_params_t *params, uint8_t id,
                                       pour_can_frame_t *reply) {
  pour_can_param_t v = {.param_id = id, .value = 0};
  (void)pour_params_get(params, id, &v.value);
  (void)pour_can_pack_param(node_id, POUR_CAN_CMD_PARAM_VALUE, &v, reply);
  return POUR_PARAM_OK;
}

static pour_param_result_t reply_ack(uint8_t node_id, const pour_can_param_request_t *r, pour_param_result_t result,
                                     pour_can_frame_t *reply) {
  const pour_can_param_ack_t a = {.request = r->cmd, .param_id = r->param_id, .result = (uint8_t)result};
  (void)pour_can_pack_param_ack(node_id, &a, reply);
  return result;
}

/* Tare and zero: the latest raw reading becomes the offset. */
static pour_param_result_t calibrate(const pour_can_param_request_t *r, const pour_can_params_env_t *env,
                                     pour_params_t *candidate) {
  if (!env->have_sample) {
    return POUR_PARAM_NO_SAMPLE;
  }
  pour_param_result_t res = POUR_PARAM_OK;
  if (r->cmd == POUR_CAN_CMD_ZERO) {
    res = pour_params_set(candidate, (uint8_t)POUR_PARAM_ID_encoder_zero, (int32_t)env->sample.encoder);
  } else {
    if ((r->scales & POUR_CAN_TARE_ROTATING) != 0u) {
      res = pour_params_set(candidate, (uint8_t)POUR_PARAM_ID_scale_rotating_tare, env->sample.scale_rotating_g);
    }
    if (res == POUR_PARAM_OK && (r->scales & POUR_CAN_TARE_TARGET) != 0u) {
      res = pour_params_set(candidate, (uint8_t)POUR_PARAM_ID_scale_target_tare, env->sample.scale_target_g);
    }
  }
  return res;
}

pour_param_result_t pour_can_params_handle(uint8_t node_id, const pour_can_param_request_t *request,
                                           pour_params_t *params, const pour_can_params_env_t *env,
                                           pour_can_frame_t *reply) {
  const pour_can_param_request_t *r = request;
  if (r->cmd == POUR_CAN_CMD_PARAM_READ) {
    return pour_param_info(r->param_id) == NULL ? reply_ack(node_id, r, POUR_PARAM_UNKNOWN_ID, reply)
                                                : reply_value(node_id, params, r->param_id, reply);
  }
  if (r->cmd == POUR_CAN_CMD_PARAM_SAVE) {
    /* Only where a write is taken: on the board an erase stalls the flash the running loop executes from. */
    pour_param_result_t saved = POUR_PARAM_NO_STORAGE;
    if (env->save != NULL) {
      saved = !env->writable ? POUR_PARAM_BUSY : (env->save(env->user, params) == POUR_OK ? POUR_PARAM_OK : POUR_PARAM_NO_STORAGE);
    }
    return reply_ack(node_id, r, saved, reply);
  }
  pour_params_t candidate = *params;
  pour_param_result_t res = POUR_PARAM_OK;
  if (r->cmd == POUR_CAN_CMD_PARAM_WRITE) {
    res = pour_params_set(&candidate, r->param_id, r->value);
  } else if (r->cmd != POUR_CAN_CMD_TARE && r->cmd != POUR_CAN_CMD_ZERO) {
    res = POUR_PARAM_UNKNOWN_ID;
  }
  if (res == POUR_PARAM_OK && !env->writable) {
    res = POUR_PARAM_BUSY;
  }
  if (res == POUR_PARAM_OK && r->cmd != POUR_CAN_CMD_PARAM_WRITE) {
    res = calibrate(r, env, &candidate);
  }
  if (res == POUR_PARAM_OK) {
    res = pour_params_check(&candidate);
  }
  if (res == POUR_PARAM_OK && env->apply != NULL && env->apply(env->user, &candidate) != POUR_OK) {
    res = POUR_PARAM_INCONSISTENT;
  }
  if (res != POUR_PARAM_OK) {
    return reply_ack(node_id, r, res, reply);
  }
  *params = candidate;
  return r->cmd == POUR_CAN_CMD_PARAM_WRITE ? reply_value(node_id, params, r->param_id, reply)
                                            : reply_ack(node_id, r, POUR_PARAM_OK, reply);
}
