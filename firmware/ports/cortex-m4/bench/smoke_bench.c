/* SPDX-License-Identifier: MIT */
/* The QEMU smoke test's bench (mps2-an386, semihosted): the hal_* calls of main.c answered by a scripted
 * host and a small plant instead of the STM32G431's pins, FDCAN, TIM1 and ADCs, so that the production loop
 * itself runs under SysTick on an emulated Cortex-M4, and the current loop's interrupt (board_drive) runs
 * 20 times a tick, called by the script as the ADC would: its samples are those of a motor whose currents
 * follow the drive's references (tests/board/ideal_drive.h), and the bucket moves with that motor's torque.
 * The script, by tick:
 *     10..169  states of a bucket that moves with the torque (StateA + StateB frames, seq counting)
 *         40  Reset: the image boots held, so the states before it start no run (the heartbeat says Held)
 *         60  CalibrationRead (while running)
 *   100..119  the hardwired e-stop line asserted
 *        130  ClearErrors
 *      170..  no more states: the input times out
 *        205  the verdict (exit status 0 or 1), after the heartbeat of tick 201
 * Checked: the current loop's periods (20 a tick), its offsets measured with the gates off and the brake
 * held meanwhile, then its compares written and its q current following the torque frame's sign;
 * DriveTelemetry with every heartbeat, without a fault, its q current that of the loop; RUN and torque
 * before the e-stop; the read answered once with the stored block (STORED, OK, its pole pairs), the run
 * going on; zero torque, brake engaged and power off in the e-stop's own tick; ESTOP latched until the clear, then RUN again through the slew limit; the stale-input fault and the
 * brake at the end; heartbeats and identity frames with the compiled-in policy hash; the watchdog fed every
 * healthy tick; the LED shown every tick with that tick's mode. */
#include <stdio.h>

#include "boot_check.h"
#include "pour/board_facts.h"
#include <stdlib.h>

#include "board_drive.h"
#include "board_params.h"
#include "params_store.h"
#include "clock.h"
#include "drive_without_cut.h"
#include "hal_brake.h"
#include "hal_calibration.h"
#include "hal_can.h"
#include "hal_drive.h"
#include "hal_estop.h"
#include "hal_led.h"
#include "hal_power.h"
#include "hal_watchdog.h"
#include "ideal_drive.h"
#include "pour/control.h"
#include "pour/weights_compiled.h"

#ifndef POUR_SMOKE_TICKS
#define POUR_SMOKE_TICKS 205u /* one heartbeat past the stale-input fault */
#endif
#define MPS2_AN386_CLOCK_HZ 25000000u
#define ESTOP_FROM 100u
#define ESTOP_TO 120u
#define CLEAR_AT 130u
#define READ_AT 60u
#define RESET_AT 40u
#define STATES_TO 170u
#define PERIODS_PER_TICK 20u /* 20 kHz PWM under the 1 kHz loop */
#define VBUS_MV 24000u
#define NTC_MV ((uint32_t)POUR_BOARD_NTC_V0_MV) /* 25 °C */

static uint32_t tick;
static bool brake = true, power;
static int32_t theta_urad, omega_urad_s;
static q15_t applied;
static pour_can_frame_t rx[3];
static unsigned rx_n, rx_i;

static struct {
  uint32_t feeds, heartbeats, identities, bad_identity, slew_steps, led_shows, led_wrong;
  uint32_t periods, gates_on_calibrating, released_calibrating, compares, iq_sign_wrong, iq_sign_checked;
  uint32_t telemetry, telemetry_faulted, telemetry_iq_wrong, calibration_read, calibration_wrong;
  uint32_t ran_before_reset, held_at_boot; /* torque frames in RUN before the Reset; heartbeats saying Held then */
  bool ran_after_read, ran, estop_same_tick, estop_latched, ran_again, stale_at_end;
  q15_t peak, last_torque;
  uint8_t last_mode;
  uint16_t last_faults;
} seen;

pour_status_t pour_clock_init(uint32_t *core_clock_hz) {
  *core_clock_hz = MPS2_AN386_CLOCK_HZ;
  return POUR_OK;
}

#define SMOKE_CRYSTAL_HZ 8000000u /* what the scripted board says it found; DriveTelemetry must carry it */
uint32_t pour_clock_crystal(void) { return SMOKE_CRYSTAL_HZ; }

/* The scripted bench's drive is calibrated (the refusal is the board's, tested in tests/board). */
pour_status_t pour_hal_calibration_load(void) { return POUR_OK; }
/* The scripted motor's encoder count is a function of the bucket's angle alone (pour_hal_can_poll): an absolute
 * encoder, whose offset a reset does not lose. */
bool pour_hal_calibration_offset_kept(void) { return true; }
int pour_hal_calibration_reason(void) { return 0; }
/* The block as the drive's default configuration would have measured it. */
pour_cal_status_t pour_hal_calibration_stored(pour_calibration_t *cal) {
  const pour_drive_config_t c = pour_drive_default_config();
  const pour_calibration_t stored = {c.r_phase_uohm, c.lq_nh, c.encoder_reversed != 0u ? -1 : 1, c.pole_pairs,
                                     c.encoder_offset};
  *cal = stored;
  return POUR_CAL_OK;
}
void pour_hal_calibration_result(pour_can_calibration_result_t *r) {
  pour_calibration_t cal;
  pour_calibration_can_result(pour_hal_calibration_stored(&cal), &cal, POUR_CAN_CAL_UNAVAILABLE, r);
}
/* A page and the flash interface's registers in RAM (mps2-an386 has no flash controller). */
static uint32_t flash_regs[POUR_FLASH_N_REGS], flash_page[POUR_FLASH_PAGE_BYTES / 4u];
const pour_flash_t *pour_hal_calibration_flash(void) {
  static const pour_flash_t f = {flash_regs, flash_page, POUR_FLASH_CAL_PAGE, 10u, NULL};
  return &f;
}
/* The parameters' page likewise, erased (never saved: the defaults). */
static uint32_t params_regs[POUR_FLASH_N_REGS], params_page[POUR_FLASH_PAGE_BYTES / 4u];
const pour_flash_t *pour_hal_params_flash(void) {
  static const pour_flash_t f = {params_regs, params_page, POUR_FLASH_PARAMS_PAGE, 10u, NULL};
  static bool erased;
  if (!erased) {
    for (uint32_t i = 0; i < POUR_FLASH_PAGE_BYTES / 4u; ++i) params_page[i] = 0xFFFFFFFFu;
    erased = true;
  }
  return &f;
}

void pour_hal_brake_init(void) { brake = true; }
void pour_hal_brake_set(bool engage) { brake = engage; }
bool pour_hal_brake_engaged(void) { return brake; }
void pour_hal_power_init(void) { power = false; }
static uint8_t led_mode = 0xFFu;
void pour_hal_led_show(uint8_t mode, bool refused) {
  led_mode = refused ? 0xFEu : mode;
  seen.led_shows++;
}
void pour_hal_power_set(bool on) { power = on; }
bool pour_hal_power_on(void) { return power; }
void pour_hal_estop_init(void) {}
bool pour_hal_estop_asserted(void) { return tick >= ESTOP_FROM && tick < ESTOP_TO; }
void pour_hal_watchdog_start(uint32_t timeout_ms) { (void)timeout_ms; }
pour_status_t pour_hal_boot_check(void) { return POUR_OK; } /* the bench has no option bytes */

pour_status_t pour_hal_can_init(uint32_t clock_hz, uint8_t node_id) {
  return clock_hz == MPS2_AN386_CLOCK_HZ && node_id == 0u ? POUR_OK : POUR_EINVAL;
}

/* --- the power stage: TIM1, the ADCs and the encoder as the current loop's interrupt sees them --------- */
static bool gates_on;
static uint16_t motor_counts; /* the motor encoder: θ through the gearbox */

pour_status_t pour_hal_drive_init(void) { return POUR_OK; }
uint16_t pour_hal_drive_period(void) { return 4250u; }
bool pour_hal_drive_sample(pour_hal_drive_sample_t *s) {
  const pour_drive_t *drv = pour_board_drive_state();
  const pour_drive_output_t *o = pour_board_drive_output();
  const q15_t id = gates_on ? o->id_ref : 0, iq = gates_on ? o->iq_ref : 0; /* last period's references */
  pour_ideal_phase_counts(drv, id, iq, motor_counts, POUR_BOARD_OFFSET_NOMINAL_COUNTS, s->phase); /* the board's bias */
  s->vbus = pour_ideal_adc_counts(&drv->config, VBUS_MV * 1000u / POUR_BOARD_VBUS_DIVIDER_MILLI);
  s->ntc = pour_ideal_adc_counts(&drv->config, NTC_MV);
  s->encoder = motor_counts;
  return true;
}
void pour_hal_drive_set_compares(const uint16_t compare[3]) {
  seen.compares += (compare[0] | compare[1] | compare[2]) != 0u ? 1u : 0u;
}
void pour_hal_drive_enable(bool on) { gates_on = on; }
void pour_hal_drive_short_low_sides(void) { gates_on = false; }

/* The PWM periods of one tick: the interrupt as the ADC's end of sequence would raise it. */
static void run_periods(void) {
  const pour_drive_t *drv = pour_board_drive_state();
  for (unsigned k = 0; k < PERIODS_PER_TICK; ++k) {
    pour_board_drive_isr();
    seen.periods++;
    if (drv->state == POUR_DRIVE_CALIBRATING) {
      seen.gates_on_calibrating += gates_on ? 1u : 0u;
      seen.released_calibrating += brake ? 0u : 1u;
    }
  }
  const int32_t mnm = power && gates_on ? pour_ideal_torque_mnm(&drv->config, pour_board_drive_output()->iq_ref, true) : 0;
  const int32_t q = mnm * 32768 / pour_weights_compiled.tau_max_mnm;
  applied = (q15_t)(q > 32767 ? 32767 : (q < -32767 ? -32767 : q));
}

/* Once per loop tick: the plant moves under the motor's torque, and this tick's frames are queued. */
void pour_hal_can_poll(void) {
  ++tick;
  run_periods();
  omega_urad_s += (int32_t)applied * 6; /* ~200 rad/s² at full torque */
  theta_urad += omega_urad_s / 1000;
  const pour_drive_config_t *dc = &pour_board_drive_state()->config;
  motor_counts = (uint16_t)(((int64_t)theta_urad * dc->gear_ratio * dc->encoder_cpr / 6283185) & (dc->encoder_cpr - 1u));
  rx_n = 0u;
  rx_i = 0u;
  if (tick >= 10u && tick < STATES_TO) {
    /* The 17-bit encoder's count at θ, rounded, wrapped below upright; 10 kg in the rotating bucket. */
    const int64_t c = ((int64_t)theta_urad * 131072 * 1000 + (theta_urad >= 0 ? 3141592654LL : -3141592654LL)) /
                      6283185307LL;
    const pour_can_sensors_t m = {(uint8_t)(tick & 0xFFu), (uint32_t)((c + 131072) % 131072), 10000, 0};
    (void)pour_can_pack_sensors(0, &m, &rx[rx_n++]);
  }
  if (tick == CLEAR_AT) {
    (void)pour_can_pack_command(0, POUR_CAN_CMD_CLEAR_ERRORS, &rx[rx_n++]);
  }
  if (tick == READ_AT) {
    (void)pour_can_pack_command(0, POUR_CAN_CMD_CALIBRATION_READ, &rx[rx_n++]);
  }
  if (tick == RESET_AT) {
    (void)pour_can_pack_command(0, POUR_CAN_CMD_RESET, &rx[rx_n++]);
  }
}

int pour_hal_can_receive(pour_can_frame_t *frame) {
  if (rx_i == rx_n) {
    return 0;
  }
  *frame = rx[rx_i++];
  return 1;
}

static void on_torque(const pour_can_torque_t *t) {
  /* The loop's q current command follows the torque's sign (this tick's, handed over before the frame). */
  const int32_t iq_ref = pour_board_drive_state()->iq_cmd_q15;
  if (power && gates_on && (t->torque > 1000 || t->torque < -1000)) {
    seen.iq_sign_checked++;
    seen.iq_sign_wrong += (t->torque > 0) == (iq_ref > 0) ? 0u : 1u;
  }
  /* Beyond the slew limit only toward zero (less torque never waits for the slew). */
  const int32_t step = (int32_t)t->torque - seen.last_torque;
  const bool toward_zero = (seen.last_torque >= 0 && t->torque >= 0 && t->torque <= seen.last_torque) ||
                           (seen.last_torque <= 0 && t->torque <= 0 && t->torque >= seen.last_torque);
  if (!toward_zero && (step > 3277 || step < -3277)) {
    seen.slew_steps++;
  }
  seen.last_torque = t->torque;
  seen.last_mode = t->mode;
  seen.led_wrong += led_mode == t->mode ? 0u : 1u; /* the LED shows the mode of the tick's torque frame */
  if (tick < RESET_AT && t->mode == POUR_MODE_RUN) {
    seen.ran_before_reset++;
  }
  if (tick < ESTOP_FROM && t->mode == POUR_MODE_RUN) {
    seen.ran = true;
    seen.peak = t->torque > seen.peak ? t->torque : seen.peak;
  }
  if (tick == READ_AT + 1u) {
    seen.ran_after_read = t->mode == POUR_MODE_RUN && power && !brake;
  }
  if (tick == ESTOP_FROM) {
    seen.estop_same_tick = t->torque == 0 && t->mode == POUR_MODE_ESTOP && brake && !power;
  }
  if (tick == CLEAR_AT - 1u) {
    seen.estop_latched = t->mode == POUR_MODE_FAULT && brake && !power;
  }
  if (tick > CLEAR_AT && tick < STATES_TO && t->mode == POUR_MODE_RUN && power && !brake) {
    seen.ran_again = true;
  }
}

int pour_hal_can_transmit(const pour_can_frame_t *frame) {
  pour_can_torque_t t;
  pour_can_heartbeat_t hb;
  pour_can_identity_t id;
  pour_can_drive_telemetry_t dt;
  pour_can_calibration_result_t cal;
  if (pour_can_unpack_torque(frame, &t) == POUR_CAN_RX_OK) {
    on_torque(&t);
  } else if (pour_can_unpack_heartbeat(frame, &hb) == POUR_CAN_RX_OK) {
    seen.heartbeats++;
    seen.last_faults = hb.faults;
    seen.held_at_boot += tick < RESET_AT && hb.held == 1u ? 1u : 0u;
  } else if (pour_can_unpack_drive_telemetry(frame, &dt) == POUR_CAN_RX_OK) {
    seen.telemetry++;
    seen.telemetry_faulted += dt.drive_faults != 0u ? 1u : 0u;
    const int32_t iq_2ma = (int32_t)pour_board_drive_output()->iq * 1000 / 1024;
    seen.telemetry_iq_wrong += dt.iq_2ma == iq_2ma && dt.crystal_4mhz == SMOKE_CRYSTAL_HZ / 4000000u ? 0u : 1u;
  } else if (pour_can_unpack_calibration_result(frame, &cal) == POUR_CAN_RX_OK) {
    const bool stored = cal.status == POUR_CAN_CAL_STORED && cal.stored == POUR_CAN_CAL_OK && tick == READ_AT &&
                        cal.pole_pairs == pour_board_drive_state()->config.pole_pairs;
    seen.calibration_read += stored ? 1u : 0u;
    seen.calibration_wrong += stored ? 0u : 1u;
  } else if (pour_can_unpack_identity(frame, &id) == POUR_CAN_RX_OK) {
    seen.identities++;
    if (id.weights_hash != pour_weights_compiled.content_hash || id.init_status != 0 ||
        id.fw_version != POUR_FIRMWARE_VERSION) {
      seen.bad_identity++;
    }
  }
  return 0;
}

/* Called by the loop once per healthy tick: the last tick of the script gives the verdict. */
void pour_hal_watchdog_feed(void) {
  seen.feeds++;
  if (tick < POUR_SMOKE_TICKS) {
    return;
  }
  seen.stale_at_end = seen.last_mode == POUR_MODE_FAULT && brake && !power;
  const bool ok = seen.ran && seen.peak > 0 && seen.estop_same_tick && seen.estop_latched && seen.ran_again &&
                  seen.stale_at_end && (seen.last_faults & POUR_FAULT_STALE_INPUT) != 0u && seen.heartbeats >= 2u &&
                  seen.identities == seen.heartbeats && seen.bad_identity == 0u && seen.slew_steps == 0u &&
                  seen.feeds + 5u >= tick && seen.led_shows + 5u >= tick && seen.led_wrong == 0u &&
                  seen.periods == tick * PERIODS_PER_TICK && seen.gates_on_calibrating == 0u &&
                  seen.released_calibrating == 0u && seen.compares > 0u && seen.iq_sign_checked > 0u &&
                  seen.iq_sign_wrong == 0u && seen.telemetry == seen.heartbeats && seen.telemetry_faulted == 0u &&
                  seen.telemetry_iq_wrong == 0u && seen.calibration_read == 1u && seen.calibration_wrong == 0u &&
                  seen.ran_after_read && seen.ran_before_reset == 0u && seen.held_at_boot > 0u;
  printf("smoke: current loop %u periods (gates on %u, brake released %u while measuring its offsets), %u with "
         "compares, q current against the torque %u of %u; drive telemetry %u (%u faulted, %u not the loop's)\n",
         (unsigned)seen.periods, (unsigned)seen.gates_on_calibrating, (unsigned)seen.released_calibrating,
         (unsigned)seen.compares, (unsigned)seen.iq_sign_wrong, (unsigned)seen.iq_sign_checked,
         (unsigned)seen.telemetry, (unsigned)seen.telemetry_faulted, (unsigned)seen.telemetry_iq_wrong);
  printf("smoke: booted held: %u heartbeat(s) saying Held, RUN before the Reset %u tick(s)\n",
         (unsigned)seen.held_at_boot, (unsigned)seen.ran_before_reset);
  printf("smoke: CalibrationRead answered with the stored block %u time(s), other calibration frames %u, RUN "
         "after it %d\n", (unsigned)seen.calibration_read, (unsigned)seen.calibration_wrong, (int)seen.ran_after_read);
  printf("smoke: %u ticks, watchdog fed %u; ran %d (peak torque %d); e-stop: zero torque, brake, power off in its "
         "tick %d, latched %d; after the clear ran %d; stale at the end %d (faults 0x%x); heartbeats %u, identities "
         "%u (%u wrong); slew-limit breaches %u; LED shown %u ticks, %u not the tick's mode: %s\n",
         (unsigned)tick, (unsigned)seen.feeds, (int)seen.ran, (int)seen.peak, (int)seen.estop_same_tick,
         (int)seen.estop_latched, (int)seen.ran_again, (int)seen.stale_at_end, (unsigned)seen.last_faults,
         (unsigned)seen.heartbeats, (unsigned)seen.identities, (unsigned)seen.bad_identity,
         (unsigned)seen.slew_steps, (unsigned)seen.led_shows, (unsigned)seen.led_wrong, ok ? "ok" : "FAILED");
  exit(ok ? 0 : 1);
}
