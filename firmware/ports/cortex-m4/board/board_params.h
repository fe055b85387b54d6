/* SPDX-License-Identifier: MIT */
/* The parameters on the board, as the Linux controller has them (docs/can.md, "Parameters"): the set in RAM,
 * loaded from flash at boot (params_store: page 62) and put in force before the first tick; each tick, the
 * sensor sample corrected by it (encoder zero, scale tares and factors) before the core sees it, and one
 * parameter request (ParamRead, ParamWrite, ParamSave, Tare, Zero) answered through pour_can_params_handle. */
#ifndef POUR_BOARD_PARAMS_H
#define POUR_BOARD_PARAMS_H

#include "flash_g4.h"
#include "pour/can_node.h"
#include "pour/control.h"
#include "pour/params.h"

/* The flash page the parameters are stored in (the board: page 62; a test: memory). */
const pour_flash_t *pour_hal_params_flash(void);

/* The defaults from ctl's configuration, then the stored set if there is one, put in force in ctl (in IDLE).
 * POUR_OK (nothing stored counts), or POUR_EPARAMS: the page holds a corrupt blob, another layout, a
 * parameter unknown or out of range, or a set the core refuses (the defaults stay in force; Identity says
 * it and the controller never drives the motor, as the Linux controller refuses to start). */
pour_status_t pour_board_params_init(pour_control_t *ctl, uint8_t node_id);

/* The sample as the core must see it (pour_params_correct with the set in force). */
void pour_board_params_correct(pour_sensors_t *sample);

/* One waiting parameter request answered onto the bus, if the node holds one. */
void pour_board_params_service(pour_control_t *ctl, pour_can_node_t *node);

/* The set in force (read-only). */
const pour_params_t *pour_board_params(void);

#endif /* POUR_BOARD_PARAMS_H */
