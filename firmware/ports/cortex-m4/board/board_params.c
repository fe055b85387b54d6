/* SPDX-License-Identifier: MIT */
#include "board_params.h"

#include <stddef.h>

#include "board_loop.h"
#include "params_store.h"
#include "pour/can_params.h"

static pour_params_t params;

pour_status_t pour_board_params_init(pour_control_t *ctl, uint8_t node_id) {
  pour_params_default(&params, &ctl->config, node_id);
  /* The candidate from flash beside the set in force: static, not on the start-up's stack, where it sat
   * under the drive's interrupt (enabled before this runs) in the thread's deepest chain (scripts/bench.sh
   * motor, stack). The start-up runs once, in thread mode only. */
  static pour_params_t stored;
  stored = params;
  uint8_t bad_id = 0u;
  const int st = pour_params_store_load(pour_hal_params_flash(), &stored, &bad_id);
  if (st == 1) {
    return POUR_OK; /* never saved: the defaults */
  }
  if (st != (int)POUR_PARAMS_BLOB_OK || pour_params_check(&stored) != POUR_PARAM_OK ||
      pour_params_apply(ctl, &stored, ctl->policy.weights) != POUR_OK) {
    return POUR_EPARAMS;
  }
  params = stored;
  return POUR_OK;
}

void pour_board_params_correct(pour_sensors_t *sample) { pour_params_correct(&params, sample); }

const pour_params_t *pour_board_params(void) { return &params; }

static pour_status_t apply(void *user, const pour_params_t *candidate) {
  pour_control_t *ctl = user;
  return pour_params_apply(ctl, candidate, ctl->policy.weights);
}

static pour_status_t save(void *user, const pour_params_t *set) {
  (void)user;
  return pour_params_store_save(pour_hal_params_flash(), set) == POUR_FLASH_OK ? POUR_OK : POUR_EINVAL;
}

void pour_board_params_service(pour_control_t *ctl, pour_can_node_t *node) {
  pour_can_param_request_t r;
  if (!pour_can_node_take_param_request(node, &r)) {
    return;
  }
  const pour_can_params_env_t env = {pour_params_writable(ctl), node->have_seq, node->sensors, apply, save, ctl};
  pour_can_frame_t reply;
  (void)pour_can_params_handle(node->config.node_id, &r, &params, &env, &reply);
  pour_board_transmit(&reply, 1u);
}
