/* SPDX-License-Identifier: MIT */
/* The STM32G431 board: core clock (PLL, 170 MHz), the brake, power and e-stop lines, the independent
 * watchdog, and FDCAN1 behind hal_can. Registers and fields from stm32g431_regs.h's table (checked against
 * ST's description of the chip by tests/board/check_registers.py).
 *   PB0  e-stop input, active low, pull-up (an open circuit asserts it)
 *   PB1  brake release, high = released (reset state low: engaged)
 *   PB2  power stage enable, high = on (reset state low: off) */
#include <stddef.h>

#include "clock.h"
#include "fdcan.h"
#include "gpio.h"
#include "hal_brake.h"
#include "hal_can.h"
#include "hal_estop.h"
#include "hal_motor.h"
#include "hal_power.h"
#include "hal_watchdog.h"
#include "safe_outputs.h"
#include "stm32g431_regs.h"

#define RCC_R POUR_PERIPH(RCC)
#define PIN_ESTOP 0u
#define PIN_BRAKE 1u
#define PIN_POWER 2u
#define PIN_CAN_RX 11u
#define PIN_CAN_TX 12u
#define AF_FDCAN1 9u
#define HSI16_HZ 16000000u
#define PLL_HZ 170000000u
#define WAIT_POLLS 100000u /* bound of every ready-flag wait: a flag that never comes is an error */

static const pour_gpio_t estop = {POUR_PERIPH(GPIOB), PIN_ESTOP};
static const pour_gpio_t brake = {POUR_PERIPH(GPIOB), PIN_BRAKE};
static const pour_gpio_t power = {POUR_PERIPH(GPIOB), PIN_POWER};

static int wait_set(volatile uint32_t *reg, uint32_t mask, uint32_t want) {
  for (uint32_t i = 0; i < WAIT_POLLS; ++i) {
    if ((*reg & mask) == want) {
      return 0;
    }
  }
  return -1;
}

static void clock_on(uint32_t enr, uint32_t mask) {
  RCC_R[enr] |= mask;
  (void)RCC_R[enr]; /* the enable takes effect before the peripheral is touched */
}

pour_status_t pour_clock_init(uint32_t *core_clock_hz) {
  volatile uint32_t *const pwr = POUR_PERIPH(PWR);
  volatile uint32_t *const flash = POUR_PERIPH(FLASH);
  const uint32_t hpre = POUR_MSK(RCC, CFGR, HPRE);
  *core_clock_hz = HSI16_HZ;
  clock_on(POUR_RCC_APB1ENR1, POUR_MSK(RCC, APB1ENR1, PWREN));
  RCC_R[POUR_RCC_CFGR] = (RCC_R[POUR_RCC_CFGR] & ~hpre) | POUR_VAL(RCC, CFGR, HPRE, 8u); /* /2 entering boost */
  pwr[POUR_PWR_CR5] &= ~POUR_MSK(PWR, CR5, R1MODE); /* range 1 boost, up to 170 MHz */
  flash[POUR_FLASH_ACR] = (flash[POUR_FLASH_ACR] & ~POUR_MSK(FLASH, ACR, LATENCY)) | POUR_VAL(FLASH, ACR, LATENCY, 4u) |
                          POUR_MSK(FLASH, ACR, PRFTEN) | POUR_MSK(FLASH, ACR, ICEN) | POUR_MSK(FLASH, ACR, DCEN);
  if (wait_set(&flash[POUR_FLASH_ACR], POUR_MSK(FLASH, ACR, LATENCY), POUR_VAL(FLASH, ACR, LATENCY, 4u)) != 0) {
    return POUR_EINVAL;
  }
  /* HSI16 / M 4 * N 85 = 340 MHz VCO, / R 2 = 170 MHz. */
  RCC_R[POUR_RCC_PLLCFGR] = POUR_VAL(RCC, PLLCFGR, PLLSRC, 2u) | POUR_VAL(RCC, PLLCFGR, PLLM, 4u - 1u) |
                          POUR_VAL(RCC, PLLCFGR, PLLN, 85u) | POUR_MSK(RCC, PLLCFGR, PLLREN) |
                          POUR_VAL(RCC, PLLCFGR, PLLR, 0u);
  RCC_R[POUR_RCC_CR] |= POUR_MSK(RCC, CR, PLLON);
  if (wait_set(&RCC_R[POUR_RCC_CR], POUR_MSK(RCC, CR, PLLRDY), POUR_MSK(RCC, CR, PLLRDY)) != 0) {
    RCC_R[POUR_RCC_CFGR] &= ~hpre;
    return POUR_EINVAL;
  }
  RCC_R[POUR_RCC_CFGR] = (RCC_R[POUR_RCC_CFGR] & ~POUR_MSK(RCC, CFGR, SW)) | POUR_VAL(RCC, CFGR, SW, 3u); /* PLL */
  if (wait_set(&RCC_R[POUR_RCC_CFGR], POUR_MSK(RCC, CFGR, SWS), POUR_VAL(RCC, CFGR, SWS, 3u)) != 0) {
    RCC_R[POUR_RCC_CFGR] &= ~hpre;
    return POUR_EINVAL;
  }
  for (volatile uint32_t i = 0; i < 200u; ++i) { /* >= 1 µs at 85 MHz before HPRE /1 */
  }
  /* HPRE, PPRE1, PPRE2 /1: 170 MHz everywhere. */
  RCC_R[POUR_RCC_CFGR] &= ~(hpre | POUR_MSK(RCC, CFGR, PPRE1) | POUR_MSK(RCC, CFGR, PPRE2));
  *core_clock_hz = PLL_HZ;
  return POUR_OK;
}

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
  pour_gpio_input(estop, POUR_GPIO_PULL_UP);
}

bool pour_hal_estop_asserted(void) { return !pour_gpio_read(estop); }

void pour_hal_watchdog_start(uint32_t timeout_ms) {
  volatile uint32_t *const iwdg = POUR_PERIPH(IWDG);
  iwdg[POUR_IWDG_KR] = 0xCCCCu; /* start (LSI 32 kHz) */
  iwdg[POUR_IWDG_KR] = 0x5555u; /* unlock PR and RLR */
  iwdg[POUR_IWDG_PR] = POUR_VAL(IWDG, PR, PR, 0u); /* /4: 8 counts per ms */
  iwdg[POUR_IWDG_RLR] = POUR_VAL(IWDG, RLR, RL, timeout_ms * 8u - 1u);
  /* the new values reached the IWDG's clock domain */
  (void)wait_set(&iwdg[POUR_IWDG_SR], POUR_MSK(IWDG, SR, PVU) | POUR_MSK(IWDG, SR, RVU) | POUR_MSK(IWDG, SR, WVU), 0u);
  iwdg[POUR_IWDG_KR] = 0xAAAAu;
}

void pour_hal_watchdog_feed(void) { POUR_PERIPH(IWDG)[POUR_IWDG_KR] = 0xAAAAu; }

/* Called from every fault exception (startup.c): the outputs to their safe levels, whatever state the
 * program is in; the watchdog then resets the MCU, which starts again with the brake engaged. */
void pour_safe_outputs(void) {
  pour_gpio_write(brake, false);
  pour_gpio_write(power, false);
  pour_hal_motor_set_torque(0);
}

static pour_fdcan_t fdcan;

pour_status_t pour_hal_can_init(uint32_t clock_hz, uint8_t node_id) {
  RCC_R[POUR_RCC_CCIPR] = (RCC_R[POUR_RCC_CCIPR] & ~POUR_MSK(RCC, CCIPR, FDCANSEL)) | POUR_VAL(RCC, CCIPR, FDCANSEL, 2u);
  clock_on(POUR_RCC_APB1ENR1, POUR_MSK(RCC, APB1ENR1, FDCANEN));
  ports_on();
  const pour_gpio_t rx = {POUR_PERIPH(GPIOA), PIN_CAN_RX};
  const pour_gpio_t tx = {POUR_PERIPH(GPIOA), PIN_CAN_TX};
  pour_gpio_alternate(rx, AF_FDCAN1);
  pour_gpio_alternate(tx, AF_FDCAN1);
  pour_fdcan_config_t fc = pour_fdcan_default_config();
  fc.kernel_clock_hz = clock_hz;
  fc.node_id = node_id;
  return pour_fdcan_init(&fdcan, pour_fdcan_stm32g4_fdcan1(), &fc);
}

void pour_hal_can_poll(void) { (void)pour_fdcan_poll(&fdcan); }

int pour_hal_can_receive(pour_can_frame_t *frame) { return pour_fdcan_receive(&fdcan, frame); }

int pour_hal_can_transmit(const pour_can_frame_t *frame) { return pour_fdcan_transmit(&fdcan, frame); }
