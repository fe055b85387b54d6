/* SPDX-License-Identifier: MIT */
#include "port_tick.h"

#include "hal_brake.h"
#include "hal_motor.h"
#include "hal_power.h"

void pour_port_outputs(const pour_control_output_t *out) {
  pour_hal_motor_set_torque(out->power ? out->torque : 0);
  if (out->brake) {
    pour_hal_brake_set(true);
    pour_hal_power_set(out->power); /* on only while a fault's stop or damping needs it, the brake engaging */
  } else {
    pour_hal_power_set(true);
    pour_hal_brake_set(false);
  }
}

void pour_port_tick(pour_control_t *ctl, const pour_control_input_t *in, pour_control_output_t *out) {
  pour_control_step(ctl, in, out);
  pour_port_outputs(out);
}
