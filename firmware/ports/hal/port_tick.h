/* SPDX-License-Identifier: MIT */
/* The tick every port runs: the core's control step, then its outputs to the motor, the brake and the power
 * stage in the order that never lets the bucket drop. Port-neutral: only the hal_* lines differ by port. */
#ifndef POUR_PORT_TICK_H
#define POUR_PORT_TICK_H

#include "pour/control.h"

/* The outputs, in order: the motor's torque (zero unless the power stage is to be on), then power on before
 * the brake releases, or the brake engaged before the power goes off (or stays on, where out asks for both:
 * a drive fault's stop while the brake engages). */
void pour_port_outputs(const pour_control_output_t *out);

/* pour_control_step, then pour_port_outputs. */
void pour_port_tick(pour_control_t *ctl, const pour_control_input_t *in, pour_control_output_t *out);

#endif /* POUR_PORT_TICK_H */
