/* SPDX-License-Identifier: MIT */
/* Cortex-M4 firmware: start-up, then the 1 kHz loop (board_loop: the bus, the core's step, the drive and its
 * calibration) above the current loop's interrupt (board_drive). Inputs come from the bus through pour::can's
 * node (can/pour.dbc: states, e-stop, stop, clear-errors, reset, CalibrationStart), from the hardwired e-stop
 * line and from the drive (its faults); the torque (the current loop's reference), the brake and the power
 * stage follow the core's output; torque, heartbeat, identity, drive-telemetry and calibration frames go
 * back on the bus. An uncalibrated drive runs the same loop with RUN refused, so that a CalibrationStart can
 * calibrate it. The same file runs in the STM32G431 image (board_stm32g431.c behind the hal_* calls) and in
 * the QEMU smoke test (smoke_bench.c, a scripted bench behind the same calls). */
#include <stdbool.h>

#include "board_drive.h"
#include "boot_check.h"
#include "board_loop.h"
#include "board_params.h"
#include "clock.h"
#include "hal_brake.h"
#include "hal_calibration.h"
#include "hal_can.h"
#include "hal_estop.h"
#include "hal_led.h"
#include "hal_motor.h"
#include "hal_power.h"
#include "hal_timer.h"
#include "hal_watchdog.h"
#include "port_tick.h"
#include "pour/can_node.h"
#include "pour/control.h"
#include "pour/weights_compiled.h"


static pour_control_t controller;
static pour_can_node_t can_node;

/* main's phases each get a frame of their own, popped (or never pushed) when another runs: the start-up's
 * configurations, the report's frames and the loop's locals would otherwise all sit in one frame, inlined into
 * the reset handler's, under the deepest chain of each. */
#define PHASE static __attribute__((noinline))

/* A controller that cannot run says why, forever: brake engaged, power off, heartbeat and identity frames
 * with the start-up status (Identity.InitStatus), and no motion whatever arrives. */
PHASE void report_forever(void) {
  pour_control_output_t out = {0};
  out.mode = (uint8_t)POUR_MODE_IDLE;
  out.brake = true;
  pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
  for (;;) {
    (void)pour_hal_timer_wait_tick();
    pour_hal_can_poll();
    pour_can_frame_t f;
    while (pour_hal_can_receive(&f) == 1) {
      (void)pour_can_node_receive(&can_node, &f);
    }
    pour_port_outputs(&out);
    pour_hal_led_show(out.mode, true);
    /* The torque frame says IDLE and 0; the heartbeat and identity frames carry the reason. */
    pour_board_transmit(tx, pour_can_node_end_tick(&can_node, &out, 0u, tx));
    pour_hal_watchdog_feed();
  }
}

/* The controller and the drive from their default configurations, which their instances copy: each
 * configuration lives only in its own function's frame, so the two are never on the stack together. */
PHASE pour_status_t controller_init(void) {
  const pour_control_config_t config = pour_control_default_config();
  const pour_status_t status = pour_control_init(&controller, &config, &pour_weights_compiled);
  /* Booted held: after any reset (power-on, the watchdog's, a software or a pin reset) no run starts until the
   * host sends Reset, even with the rig's samples coming (IEC 60204-1 §7.5 and §9.2.5.4.1: no restart on its
   * own after a reset or a power restoration; docs/safety.md). */
  pour_control_hold(&controller);
  return status;
}

PHASE pour_status_t drive_init(void) {
  /* Uncalibrated, the drive never follows a torque (RUN refused) until a CalibrationStart calibrates it. A stored
   * calibration whose electrical offset did not survive the reset (pour_hal_calibration_offset_kept) is the same
   * for the drive: it would commutate up to 180 electrical degrees off (the virtual board's finding,
   * docs/virtual-board.md), so RUN waits for a CalibrationStart in this power cycle, and Identity says why
   * (POUR_EALIGN). R, L and the pole pairs stay stored (the block is not touched). */
  const bool calibrated = pour_hal_calibration_load() == POUR_OK;
  const bool offset = calibrated && pour_hal_calibration_offset_kept();
  const pour_drive_config_t drive = pour_drive_default_config();
  const pour_status_t status = pour_board_drive_init(&drive, pour_weights_compiled.tau_max_mnm, offset);
  if (status != POUR_OK || offset) {
    return status;
  }
  return calibrated ? POUR_EALIGN : POUR_ECALIBRATION; /* what Identity says until then */
}

/* The start-up statuses under which the loop still runs, RUN refused, so that a CalibrationStart can fix them. */
static bool waits_for_calibration(pour_status_t status) {
  return status == POUR_ECALIBRATION || status == POUR_EALIGN;
}

/* The start-up: the board at safe levels, the clock, the watchdog, the controller, the drive and the node.
 * Returns false when the node or the bus cannot start; *status is what Identity says. The drive's interrupt
 * is enabled inside (pour_board_drive_init, last), so the stack of this chain counts with the interrupt's. */
PHASE bool start_up(pour_status_t *status_out) {
  /* Safe levels first: the brake engaged and the power off until the core says otherwise. */
  pour_hal_brake_init();
  pour_hal_power_init();
  pour_hal_motor_init();
  pour_hal_estop_init();
  uint32_t clock_hz = 0u;
  const pour_status_t clock_status = pour_clock_init(&clock_hz);
  pour_hal_watchdog_start(POUR_WATCHDOG_TIMEOUT_MS);
  pour_hal_timer_init(clock_hz);

  pour_status_t status = controller_init();
  if (status == POUR_OK) {
    status = pour_hal_boot_check(); /* option bytes that would boot the ROM bootloader: said, never run */
  }
  if (status == POUR_OK) {
    status = clock_status; /* without its clock the loop would still run, but not as measured: refuse */
  }
  if (status == POUR_OK) {
    status = drive_init();
  }
  pour_can_node_config_t nc = pour_can_node_default_config();
  if (status == POUR_OK || waits_for_calibration(status)) {
    /* The stored parameters before the first tick (a stored node id too); a set that cannot be trusted is
     * refused as a policy or a clock would be. */
    const pour_status_t params = pour_board_params_init(&controller, nc.node_id);
    status = params != POUR_OK ? params : status;
    nc.node_id = pour_board_params()->node_id;
  }
  *status_out = status;
  nc.identity.weights_hash = pour_weights_compiled.content_hash;
  nc.identity.tau_max_cnm = (uint16_t)(pour_weights_compiled.tau_max_mnm / 10);
  nc.identity.init_status = (int8_t)status;
  nc.can_calibrate = true;
  pour_can_calibration_result_t calibration;
  pour_hal_calibration_result(&calibration); /* the stored calibration a CalibrationStart is answered with */
  if (pour_can_node_init(&can_node, &nc) != POUR_OK || pour_hal_can_init(clock_hz, nc.node_id) != POUR_OK) {
    return false;
  }
  pour_can_node_set_calibration(&can_node, &calibration);
  return true;
}

/* The 1 kHz loop, for ever. */
PHASE void run(void) {
  pour_board_loop_init(&can_node);
  uint32_t overruns = 0u;
  for (;;) {
    const uint32_t missed = pour_hal_timer_wait_tick();
    overruns += missed;
    pour_board_loop_tick(&controller, &can_node, overruns);
    if (missed == 0u) {
      pour_hal_watchdog_feed(); /* a healthy tick: on time, stepped, outputs written */
    }
  }
}

int main(void) {
  pour_status_t status = POUR_OK;
  if (!start_up(&status)) {
    /* No bus: nobody can command or hear this controller. Brake engaged, power off; without a feed the
     * watchdog resets the MCU, which tries again. */
    for (;;) {
    }
  }
  if (status != POUR_OK && !waits_for_calibration(status)) {
    report_forever();
  }
  run();
}
