/* SPDX-License-Identifier: MIT */
/* The STM32G431 board: core clock (PLL, 170 MHz), the brake, power and e-stop lines, the independent
 * watchdog, and FDCAN1 behind hal_can. Register addresses and fields from RM0440.
 *   PB0  e-stop input, active low, pull-up (an open circuit asserts it)
 *   PB1  brake release, high = released (reset state low: engaged)
 *   PB2  power stage enable, high = on (reset state low: off) */
#include <stddef.h>

#include "clock.h"
#include "fdcan.h"
#include "hal_brake.h"
#include "hal_can.h"
#include "hal_estop.h"
#include "hal_motor.h"
#include "hal_power.h"
#include "hal_watchdog.h"
#include "safe_outputs.h"

#define REG(addr) (*(volatile uint32_t *)(uintptr_t)(addr))
#define RCC_CR REG(0x40021000u)
#define RCC_CFGR REG(0x40021008u)
#define RCC_PLLCFGR REG(0x4002100Cu)
#define RCC_AHB2ENR REG(0x4002104Cu)
#define RCC_APB1ENR1 REG(0x40021058u)
#define PWR_CR5 REG(0x40007080u)
#define FLASH_ACR REG(0x40022000u)
#define IWDG_KR REG(0x40003000u)
#define IWDG_PR REG(0x40003004u)
#define IWDG_RLR REG(0x40003008u)
#define IWDG_SR REG(0x4000300Cu)
#define GPIOB_MODER REG(0x48000400u)
#define GPIOB_PUPDR REG(0x4800040Cu)
#define GPIOB_IDR REG(0x48000410u)
#define GPIOB_ODR REG(0x48000414u)
#define GPIOB_BSRR REG(0x48000418u)

#define PIN_ESTOP 0u
#define PIN_BRAKE 1u
#define PIN_POWER 2u
#define HSI16_HZ 16000000u
#define PLL_HZ 170000000u
#define WAIT_POLLS 100000u /* bound of every ready-flag wait: a flag that never comes is an error */

static int wait_set(volatile uint32_t *reg, uint32_t mask, uint32_t want) {
  for (uint32_t i = 0; i < WAIT_POLLS; ++i) {
    if ((*reg & mask) == want) {
      return 0;
    }
  }
  return -1;
}

pour_status_t pour_clock_init(uint32_t *core_clock_hz) {
  *core_clock_hz = HSI16_HZ;
  RCC_APB1ENR1 |= 1u << 28;                               /* PWREN */
  (void)RCC_APB1ENR1;
  RCC_CFGR = (RCC_CFGR & ~(0xFu << 4)) | (0x8u << 4);     /* HPRE /2 while entering boost mode */
  PWR_CR5 &= ~(1u << 8);                                  /* R1MODE = 0: range 1 boost, up to 170 MHz */
  FLASH_ACR = (FLASH_ACR & ~0xFu) | 4u | (7u << 8);       /* 4 wait states; prefetch, I- and D-cache on */
  if (wait_set(&FLASH_ACR, 0xFu, 4u) != 0) {
    return POUR_EINVAL;
  }
  /* HSI16 / M 4 * N 85 = 340 MHz VCO, / R 2 = 170 MHz. */
  RCC_PLLCFGR = 2u | (3u << 4) | (85u << 8) | (1u << 24); /* PLLSRC HSI16, PLLM-1, PLLN, PLLREN; PLLR /2 */
  RCC_CR |= 1u << 24;                                     /* PLLON */
  if (wait_set(&RCC_CR, 1u << 25, 1u << 25) != 0) {       /* PLLRDY */
    RCC_CFGR &= ~(0xFu << 4);
    return POUR_EINVAL;
  }
  RCC_CFGR = (RCC_CFGR & ~3u) | 3u;                       /* SW = PLL */
  if (wait_set(&RCC_CFGR, 3u << 2, 3u << 2) != 0) {       /* SWS = PLL */
    RCC_CFGR &= ~(0xFu << 4);
    return POUR_EINVAL;
  }
  for (volatile uint32_t i = 0; i < 200u; ++i) {          /* >= 1 µs at 85 MHz before HPRE /1 */
  }
  RCC_CFGR &= ~((0xFu << 4) | (7u << 8) | (7u << 11));   /* HPRE, PPRE1, PPRE2 /1: 170 MHz everywhere */
  *core_clock_hz = PLL_HZ;
  return POUR_OK;
}

static void gpiob_output(uint32_t pin) {
  RCC_AHB2ENR |= 1u << 1; /* GPIOBEN */
  (void)RCC_AHB2ENR;
  GPIOB_BSRR = 1u << (pin + 16u); /* low first: the safe level */
  GPIOB_MODER = (GPIOB_MODER & ~(3u << (2u * pin))) | (1u << (2u * pin));
}

void pour_hal_brake_init(void) { gpiob_output(PIN_BRAKE); }

void pour_hal_brake_set(bool engage) { GPIOB_BSRR = engage ? 1u << (PIN_BRAKE + 16u) : 1u << PIN_BRAKE; }

bool pour_hal_brake_engaged(void) { return (GPIOB_ODR & (1u << PIN_BRAKE)) == 0u; }

void pour_hal_power_init(void) { gpiob_output(PIN_POWER); }

void pour_hal_power_set(bool on) { GPIOB_BSRR = on ? 1u << PIN_POWER : 1u << (PIN_POWER + 16u); }

bool pour_hal_power_on(void) { return (GPIOB_ODR & (1u << PIN_POWER)) != 0u; }

void pour_hal_estop_init(void) {
  RCC_AHB2ENR |= 1u << 1;
  (void)RCC_AHB2ENR;
  GPIOB_MODER &= ~(3u << (2u * PIN_ESTOP));                                         /* input */
  GPIOB_PUPDR = (GPIOB_PUPDR & ~(3u << (2u * PIN_ESTOP))) | (1u << (2u * PIN_ESTOP)); /* pull-up */
}

bool pour_hal_estop_asserted(void) { return (GPIOB_IDR & (1u << PIN_ESTOP)) == 0u; }

void pour_hal_watchdog_start(uint32_t timeout_ms) {
  IWDG_KR = 0xCCCCu; /* start (LSI 32 kHz) */
  IWDG_KR = 0x5555u; /* unlock PR and RLR */
  IWDG_PR = 0u;      /* /4: 8 counts per ms */
  IWDG_RLR = timeout_ms * 8u - 1u;
  (void)wait_set(&IWDG_SR, 0x7u, 0u); /* the new values reached the IWDG's clock domain */
  IWDG_KR = 0xAAAAu;
}

void pour_hal_watchdog_feed(void) { IWDG_KR = 0xAAAAu; }

/* Called from every fault exception (startup.c): the outputs to their safe levels, whatever state the
 * program is in; the watchdog then resets the MCU, which starts again with the brake engaged. */
void pour_safe_outputs(void) {
  GPIOB_BSRR = (1u << (PIN_BRAKE + 16u)) | (1u << (PIN_POWER + 16u));
  pour_hal_motor_set_torque(0);
}

static pour_fdcan_t fdcan;

pour_status_t pour_hal_can_init(uint32_t clock_hz, uint8_t node_id) {
  pour_fdcan_stm32g4_board_init();
  pour_fdcan_config_t fc = pour_fdcan_default_config();
  fc.kernel_clock_hz = clock_hz;
  fc.node_id = node_id;
  return pour_fdcan_init(&fdcan, pour_fdcan_stm32g4_fdcan1(), &fc);
}

void pour_hal_can_poll(void) { (void)pour_fdcan_poll(&fdcan); }

int pour_hal_can_receive(pour_can_frame_t *frame) { return pour_fdcan_receive(&fdcan, frame); }

int pour_hal_can_transmit(const pour_can_frame_t *frame) { return pour_fdcan_transmit(&fdcan, frame); }
