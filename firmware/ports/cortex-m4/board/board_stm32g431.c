/* SPDX-License-Identifier: MIT */
/* The ST B-G431B-ESC1 board (docs/bringup.md: the wiring and each pin's reason; pour/board_facts.h: every pin
 * and its source): core clock (crystal, PLL, 170 MHz), the brake, power and e-stop lines, the independent
 * watchdog, the option bytes' boot check, the LED, and FDCAN1 behind hal_can. Registers and fields from
 * stm32g431_regs.h's table (checked against ST's description of the chip by tests/board/check_registers.py).
 *   PB8   e-stop input (J8's Z, the board's 10 kΩ pull-up to 3.3 V, BOOT0): a normally-closed contact to ground
 *         holds it low; an open contact or a broken wire reads high = asserted
 *   PB3   brake release (the ST-LINK VCP's pad), high = released; an external 10 kΩ pull-down keeps the brake
 *         engaged through reset, flashing (SWD leaves PB3 alone) and the ROM bootloader (which never drives it)
 *   PA15  power stage enable (the PWM-input pad), high = on; an external 4.7 kΩ pull-down holds it under 0.52 V
 *         against the JTDI pull-up the chip applies from reset until this firmware configures it
 *   PA11, PB9  FDCAN1 RX, TX; PC11 transceiver shutdown, low = on; PC14 bus termination, high = on
 *   PC6   LED (red), high = on */
#include <stddef.h>

#include "adc_inj.h"
#include "board_params.h"
#include "boot_check.h"
#include "calibration_store.h"
#include "clock.h"
#include "encoder_tim4.h"
#include "fdcan.h"
#include "gpio.h"
#include "hal_drive.h"
#include "hal_drive_g4.h"
#include "ocp.h"
#include "opamp.h"
#include "params_store.h"
#include "pour/board_facts.h"
#include "pwm_tim1.h"
#include "hal_brake.h"
#include "hal_calibration.h"
#include "hal_can.h"
#include "hal_estop.h"
#include "hal_led.h"
#include "hal_timer.h"
#include "led.h"
#include "hal_motor.h"
#include "hal_power.h"
#include "hal_watchdog.h"
#include "iwdg.h"
#include "safe_outputs.h"
#include "stm32g431_regs.h"

#define RCC_R POUR_PERIPH(RCC)
#define CAN_TERMINATED true /* this node ends the bench's bus (the rig's sensor node is the other end) */
#define WAIT_POLLS 100000u /* bound of every ready-flag wait: a flag that never comes is an error */

/* A pin of pour/board_facts.h's table by its name: its port's registers (GPIOA + 0x400 per port) and number. */
#define BOARD_PIN(name)                                                                                      \
  {(volatile uint32_t *)(uintptr_t)(POUR_GPIOA_BASE + 0x400u * (uint32_t)POUR_BOARD_PIN_##name##_PORT),          \
   (uint8_t)POUR_BOARD_PIN_##name##_PIN}
static const pour_gpio_t estop = BOARD_PIN(ESTOP);
static const pour_gpio_t brake = BOARD_PIN(BRAKE);
static const pour_gpio_t power = BOARD_PIN(POWER);
static const pour_gpio_t led = BOARD_PIN(LED);

/* A pin and its alternate function, both from the table. */
typedef struct {
  pour_gpio_t pin;
  uint8_t af;
} af_pin_t;
#define AF_PIN(name) {BOARD_PIN(name), (uint8_t)POUR_BOARD_PIN_##name##_AF}
static const af_pin_t can_pins[] = {AF_PIN(CAN_RX), AF_PIN(CAN_TX)};
static const af_pin_t gates[] = {AF_PIN(PWM_UH), AF_PIN(PWM_VH), AF_PIN(PWM_WH),
                                 AF_PIN(PWM_UL), AF_PIN(PWM_VL), AF_PIN(PWM_WL)};
static const af_pin_t encoder_pins[] = {AF_PIN(ENC_A), AF_PIN(ENC_B)};
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))
static const pour_gpio_t can_shutdown = BOARD_PIN(CAN_SHDN);
static const pour_gpio_t can_termination = BOARD_PIN(CAN_TERM);

static pour_ocp_t ocp;

static void clock_on(uint32_t enr, uint32_t mask) {
  RCC_R[enr] |= mask;
  (void)RCC_R[enr]; /* the enable takes effect before the peripheral is touched */
}

static uint32_t crystal_hz;

pour_status_t pour_clock_init(uint32_t *core_clock_hz) {
  const pour_clock_hw_t hw = {POUR_PERIPH(RCC), POUR_PERIPH(PWR), POUR_PERIPH(FLASH), POUR_PERIPH(LPTIM1),
                              (volatile uint32_t *)(uintptr_t)POUR_SYSTICK_BASE};
  const pour_clock_config_t config = pour_clock_default_config();
  pour_clock_source_t source;
  return pour_clock_setup(&hw, &config, core_clock_hz, &source, &crystal_hz);
}

uint32_t pour_clock_crystal(void) { return crystal_hz; }

pour_status_t pour_hal_boot_check(void) { return pour_boot_check_optr(POUR_PERIPH(FLASH)[POUR_FLASH_OPTR]); }

static void ports_on(void) {
  clock_on(POUR_RCC_AHB2ENR, POUR_MSK(RCC, AHB2ENR, GPIOAEN) | POUR_MSK(RCC, AHB2ENR, GPIOBEN) |
                                 POUR_MSK(RCC, AHB2ENR, GPIOCEN));
}

void pour_hal_brake_init(void) {
  ports_on();
  pour_gpio_output(brake, false);
}

void pour_hal_brake_set(bool engage) { pour_gpio_write(brake, !engage); }

bool pour_hal_brake_engaged(void) { return !pour_gpio_driven(brake); }

void pour_hal_power_init(void) {
  ports_on();
  pour_gpio_output(power, false);
}

void pour_hal_power_set(bool on) { pour_gpio_write(power, on); }

bool pour_hal_power_on(void) { return pour_gpio_driven(power); }

void pour_hal_estop_init(void) {
  ports_on();
  pour_gpio_output(led, false);
  pour_gpio_input(estop, POUR_GPIO_PULL_NONE); /* the board's 10 kΩ pull-up: open reads asserted */
}

bool pour_hal_estop_asserted(void) { return pour_gpio_read(estop); }

void pour_hal_watchdog_start(uint32_t timeout_ms) {
  (void)pour_iwdg_set(POUR_PERIPH(IWDG), timeout_ms, WAIT_POLLS); /* values that never settle: the old ones hold */
}

void pour_hal_watchdog_set_timeout(uint32_t timeout_ms) { (void)pour_iwdg_set(POUR_PERIPH(IWDG), timeout_ms, WAIT_POLLS); }

/* Around a flash page's erase and program: the watchdog outlasts the stall, then the loop's timeout again. */
static void flash_stall(bool begin) {
  pour_hal_watchdog_set_timeout(begin ? POUR_WATCHDOG_FLASH_MS : POUR_WATCHDOG_TIMEOUT_MS);
}

void pour_hal_watchdog_feed(void) { POUR_PERIPH(IWDG)[POUR_IWDG_KR] = 0xAAAAu; }

/* Called from every fault exception (startup.c): the outputs to their safe levels, whatever state the
 * program is in; the watchdog then resets the MCU, which starts again with the brake engaged. */
void pour_safe_outputs(void) {
  pour_gpio_write(brake, false);
  pour_gpio_write(power, false);
  pour_hal_drive_short_low_sides(); /* damping, never coasting, until the brake holds */
  pour_hal_motor_set_torque(0);
}

void pour_hal_led_show(uint8_t mode, bool refused) { pour_gpio_write(led, pour_led_pattern(mode, refused, pour_hal_timer_ticks())); }

static pour_fdcan_t fdcan;

pour_status_t pour_hal_can_init(uint32_t clock_hz, uint8_t node_id) {
  RCC_R[POUR_RCC_CCIPR] = (RCC_R[POUR_RCC_CCIPR] & ~POUR_MSK(RCC, CCIPR, FDCANSEL)) | POUR_VAL(RCC, CCIPR, FDCANSEL, 2u);
  clock_on(POUR_RCC_APB1ENR1, POUR_MSK(RCC, APB1ENR1, FDCANEN));
  ports_on();
  for (unsigned i = 0; i < COUNT(can_pins); ++i) {
    pour_gpio_alternate(can_pins[i].pin, can_pins[i].af);
  }
  pour_gpio_output(can_termination, CAN_TERMINATED);
  pour_gpio_output(can_shutdown, false);
  pour_fdcan_config_t fc = pour_fdcan_default_config();
  fc.kernel_clock_hz = clock_hz;
  fc.node_id = node_id;
  return pour_fdcan_init(&fdcan, pour_fdcan_stm32g4_fdcan1(), &fc);
}

void pour_hal_can_poll(void) { (void)pour_fdcan_poll(&fdcan); }

int pour_hal_can_receive(pour_can_frame_t *frame) { return pour_fdcan_receive(&fdcan, frame); }

int pour_hal_can_transmit(const pour_can_frame_t *frame) { return pour_fdcan_transmit(&fdcan, frame); }

/* The motor's power stage (hal_drive): the gates, the encoder and the converters' pins. */
/* OPAMP inputs and outputs, the bus divider, the NTC. */
static const pour_gpio_t analog_pins[] = {BOARD_PIN(SHUNT_U), BOARD_PIN(SHUNT_U_M), BOARD_PIN(AMP_U), BOARD_PIN(SHUNT_V),
                                          BOARD_PIN(SHUNT_V_M), BOARD_PIN(AMP_V),   BOARD_PIN(SHUNT_W), BOARD_PIN(SHUNT_W_M),
                                          BOARD_PIN(AMP_W),   BOARD_PIN(VBUS),      BOARD_PIN(NTC)};
#define ENCODER_FILTER 6u   /* f_DTS / 4, N = 6: 141 ns at 170 MHz */
#define OPAMP_GAIN ((uint32_t)POUR_BOARD_PGA_GAIN) /* input/bias on VINM0 (opamp.h) */
#define ADC_REGULATOR_WAIT 4000u /* >= 20 µs at 170 MHz (>= 4 cycles a pass) */


/* The NVIC is the core's (ARMv7-M): the same addresses on every Cortex-M4. */
#define NVIC_ISER0 (*(volatile uint32_t *)0xE000E100u)
#define NVIC_ICER0 (*(volatile uint32_t *)0xE000E180u)

void pour_hal_drive_mask(bool masked) {
  if (masked) {
    NVIC_ICER0 = 1u << POUR_ADC_IRQ;
    __asm volatile("dsb\n isb" ::: "memory"); /* no interrupt of the loop's after this returns */
  } else {
    NVIC_ISER0 = 1u << POUR_ADC_IRQ;
  }
}

pour_status_t pour_hal_drive_init(void) {
  for (unsigned i = 0; i < COUNT(gates); ++i) {
    pour_gpio_output(gates[i].pin, false); /* all six off while TIM1 is set up */
  }
  clock_on(POUR_RCC_APB2ENR, POUR_MSK(RCC, APB2ENR, TIM1EN) | POUR_MSK(RCC, APB2ENR, SYSCFGEN));
  clock_on(POUR_RCC_APB1ENR1, POUR_MSK(RCC, APB1ENR1, TIM4EN));
  clock_on(POUR_RCC_AHB2ENR, POUR_MSK(RCC, AHB2ENR, ADC12EN) | POUR_MSK(RCC, AHB2ENR, DAC3EN));
  for (unsigned i = 0; i < COUNT(analog_pins); ++i) {
    pour_gpio_analog(analog_pins[i]);
  }
  const pour_pwm_config_t pc = pour_pwm_default_config();
  pour_pwm_t pwm;
  pour_adc_t adc;
  if (pour_pwm_init(&pwm, POUR_PERIPH(TIM1), &pc) != POUR_OK) {
    return POUR_EINVAL;
  }
  for (unsigned i = 0; i < COUNT(gates); ++i) {
    pour_gpio_speed(gates[i].pin, POUR_GPIO_SPEED_HIGH); /* [mcsdk] HAL_TIM_MspPostInit GPIO_SPEED_FREQ_HIGH */
    pour_gpio_alternate(gates[i].pin, gates[i].af);      /* the timer, all six off, takes the pins */
  }
  for (unsigned i = 0; i < COUNT(encoder_pins); ++i) {
    pour_gpio_alternate(encoder_pins[i].pin, encoder_pins[i].af);
  }
  if (pour_opamp_init(POUR_PERIPH(OPAMP), OPAMP_GAIN) != POUR_OK ||
      pour_encoder_init(POUR_PERIPH(TIM4), ENCODER_FILTER, 0) != POUR_OK ||
      pour_adc_init(&adc, POUR_PERIPH(ADC1), POUR_PERIPH(ADC2), POUR_PERIPH(ADC12_COMMON), WAIT_POLLS,
                    ADC_REGULATOR_WAIT) != POUR_OK) {
    return POUR_EINVAL;
  }
  pour_hal_drive_attach(&pwm, &adc, POUR_PERIPH(TIM4), &ocp);
  pour_hal_drive_mask(false); /* the current loop runs from now on (ADC1's end of sequence: pour_adc_init) */
  return POUR_OK;
}

pour_status_t pour_hal_drive_arm_overcurrent(const uint16_t offset_counts[3]) {
  const pour_ocp_config_t oc = pour_ocp_default_config();
  return pour_ocp_init(&ocp, POUR_PERIPH(COMP), POUR_PERIPH(DAC3), &oc, offset_counts);
}


/* The calibration: the block in the page the linker script leaves (hal_calibration). */
static pour_calibration_t calibration;
static pour_cal_status_t calibration_status = POUR_CAL_EMPTY;

static const pour_flash_t calibration_flash = {
    POUR_PERIPH(FLASH), (volatile uint32_t *)(uintptr_t)POUR_FLASH_CAL_ADDR, POUR_FLASH_CAL_PAGE, WAIT_POLLS, flash_stall};

/* A double ECC error on a flash read (a page left half-erased by a lost supply: RM0440 §3.3.5) raises the NMI
 * with FLASH_ECCR.ECCD set. Taken as a fault, it would reset the board for ever, reading the same page at
 * every start: instead it is cleared and remembered, and the page read under it is corrupt. Any other NMI (the
 * clock security system) is a fault. */
static volatile bool flash_ecc_error;

void NMI_Handler(void) {
  volatile uint32_t *const f = POUR_PERIPH(FLASH);
  if ((f[POUR_FLASH_ECCR] & POUR_MSK(FLASH, ECCR, ECCD)) == 0u) {
    Fault_Handler();
  }
  f[POUR_FLASH_ECCR] |= POUR_MSK(FLASH, ECCR, ECCD); /* write 1 to clear */
  flash_ecc_error = true;
}

pour_status_t pour_hal_calibration_load(void) {
  flash_ecc_error = false;
  calibration_status = pour_calibration_load(&calibration_flash, &calibration);
  if (flash_ecc_error) {
    calibration_status = POUR_CAL_CORRUPT; /* a word of the page did not read back: never trusted */
  }
  return calibration_status == POUR_CAL_OK ? POUR_OK : POUR_ECALIBRATION;
}

int pour_hal_calibration_reason(void) { return (int)calibration_status; }

bool pour_hal_calibration_offset_kept(void) { return false; } /* TIM4 from 0 at every start, no index: hal_calibration.h */

pour_cal_status_t pour_hal_calibration_stored(pour_calibration_t *cal) {
  *cal = calibration;
  return calibration_status;
}

const pour_flash_t *pour_hal_calibration_flash(void) { return &calibration_flash; }

/* The parameters: the page before the calibration's (params_store.h). */
static const pour_flash_t params_flash = {POUR_PERIPH(FLASH), (volatile uint32_t *)(uintptr_t)POUR_FLASH_PARAMS_ADDR,
                                          POUR_FLASH_PARAMS_PAGE, WAIT_POLLS, flash_stall};

const pour_flash_t *pour_hal_params_flash(void) { return &params_flash; }

void pour_hal_calibration_result(pour_can_calibration_result_t *r) {
  pour_calibration_can_result(calibration_status, &calibration, POUR_CAN_CAL_UNAVAILABLE, r);
}
