/* SPDX-License-Identifier: MIT */
/* Cortex-M4 firmware: the 1 kHz loop around the control step. Inputs come from the CAN port (see
 * poll_input); until it is wired, no state ever arrives and the controller stays in IDLE at safe torque. */
#include <stdbool.h>

#include "hal_motor.h"
#include "hal_timer.h"
#include "pour/control.h"
#include "pour/weights_compiled.h"

/* STM32G431 reset clock: HSI16. A PLL set-up to 170 MHz changes only this number. */
#ifndef POUR_CORE_CLOCK_HZ
#define POUR_CORE_CLOCK_HZ 16000000u
#endif

static pour_control_t controller;

/* Fills one tick's inputs. The FDCAN driver and the CAN node (fdcan.c, can_node.c) plug in here. */
static void poll_input(pour_control_input_t *in) {
  in->state_fresh = false;
  in->estop = false;
  in->clear_faults = false;
}

int main(void) {
  pour_hal_motor_init();
  const pour_control_config_t config = pour_control_default_config();
  if (pour_control_init(&controller, &config, &pour_weights_compiled) != POUR_OK) {
    for (;;) { /* a policy that fails validation never drives the motor */
    }
  }
  pour_hal_timer_init(POUR_CORE_CLOCK_HZ);
  pour_control_input_t in = {false, {0u, 0, 0, 0, 0, 0}, false, false};
  pour_control_output_t out;
  for (;;) {
    (void)pour_hal_timer_wait_tick();
    poll_input(&in);
    pour_control_step(&controller, &in, &out);
    pour_hal_motor_set_torque(out.torque);
  }
}
