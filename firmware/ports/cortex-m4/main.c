/* SPDX-License-Identifier: MIT */
/* Cortex-M4 firmware: the 1 kHz loop around the control step. Inputs come from FDCAN1 through the core's
 * CAN node (can/pour.dbc: states, e-stop, clear-errors); torque and heartbeat frames go back the same way.
 * Built with POUR_SMOKE_TICKS (QEMU, semihosted), the same loop runs that many ticks on a scripted
 * input and checks what the controller did: the on-target smoke test of SysTick and the loop. */
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

#ifdef POUR_SMOKE_TICKS
#include <stdio.h>

/* Ticks 10..59 bring a fresh state of a bucket that moves with the torque (the supervisor judges
 * physics: a scripted bucket that never moved would be a frozen encoder), then the input stops. */
static void poll_input(pour_control_input_t *in, uint32_t tick) {
  static int32_t omega_urad_s = 0;
  in->state_fresh = tick >= 10u && tick < 60u;
  if (in->state_fresh) {
    omega_urad_s += (int32_t)controller.safety.torque * 6; /* ~200 rad/s² at full torque */
    in->state.theta_urad += omega_urad_s / 1000;
    in->state.omega_urad_s = omega_urad_s;
  }
  in->state.seq = tick;
  in->state.v_rotating = 32767;
  in->estop = false;
  in->clear_faults = false;
}
#else
#include "fdcan.h"
#include "pour/can_node.h"

static pour_can_node_t can_node;
static pour_fdcan_t fdcan;

/* Fills one tick's inputs from the frames received since the last tick (the latest state wins). */
static void poll_input(pour_control_input_t *in, uint32_t tick) {
  (void)tick;
  pour_can_frame_t f;
  (void)pour_fdcan_poll(&fdcan);
  while (pour_fdcan_receive(&fdcan, &f) == 1) {
    (void)pour_can_node_receive(&can_node, &f);
  }
  pour_can_node_begin_tick(&can_node, in);
}

/* CAN up: pins and clocks, the peripheral, the node. If it fails no state arrives: IDLE, safe torque. */
static void can_init(void) {
  pour_fdcan_stm32g4_board_init();
  pour_fdcan_config_t fc = pour_fdcan_default_config();
  fc.kernel_clock_hz = POUR_CORE_CLOCK_HZ;
  (void)pour_fdcan_init(&fdcan, pour_fdcan_stm32g4_fdcan1(), &fc);
  pour_can_node_config_t nc = pour_can_node_default_config();
  nc.identity.weights_hash = pour_weights_compiled.content_hash;
  nc.identity.tau_max_cnm = (uint16_t)(pour_weights_compiled.tau_max_mnm / 10);
  (void)pour_can_node_init(&can_node, &nc);
}
#endif

int main(void) {
  pour_hal_motor_init();
  const pour_control_config_t config = pour_control_default_config();
  if (pour_control_init(&controller, &config, &pour_weights_compiled) != POUR_OK) {
    for (;;) { /* a policy that fails validation never drives the motor */
    }
  }
  pour_hal_timer_init(POUR_CORE_CLOCK_HZ);
  pour_control_input_t in = {false, {0u, 0, 0, 0, 0, 0}, false, false, false, false, false};
  pour_control_output_t out;
#ifdef POUR_SMOKE_TICKS
  uint32_t missed = 0u;
  bool ran = false;
  q15_t peak = 0;
  for (uint32_t tick = 0; tick < POUR_SMOKE_TICKS; ++tick) {
    missed += pour_hal_timer_wait_tick();
    poll_input(&in, tick);
    pour_control_step(&controller, &in, &out);
    pour_hal_motor_set_torque(out.torque);
    ran = ran || out.mode == POUR_MODE_RUN;
    peak = out.torque > peak ? out.torque : peak;
  }
  const bool ok = ran && peak > 0 && out.mode == POUR_MODE_FAULT && out.faults == POUR_FAULT_STALE_INPUT &&
                  pour_hal_motor_torque() == config.safe_torque && pour_hal_timer_ticks() >= POUR_SMOKE_TICKS;
  printf("smoke: %u ticks (%u missed), ran %d, peak torque %d, final mode %u faults 0x%x torque %d: %s\n",
         (unsigned)pour_hal_timer_ticks(), (unsigned)missed, (int)ran, (int)peak, (unsigned)out.mode,
         (unsigned)out.faults, (int)pour_hal_motor_torque(), ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
#else
  can_init();
  uint32_t overruns = 0u;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  for (uint32_t tick = 0;; ++tick) {
    overruns += pour_hal_timer_wait_tick();
    poll_input(&in, tick);
    pour_control_step(&controller, &in, &out);
    const uint8_t n_tx = pour_can_node_end_tick(&can_node, &out, overruns, tx);
    pour_hal_motor_set_torque(out.torque);
    for (uint8_t i = 0; i < n_tx; ++i) {
      (void)pour_fdcan_transmit(&fdcan, &tx[i]);
    }
  }
#endif
}
