/* SPDX-License-Identifier: MIT */
/* Prints the Cortex-M4 port's register tables (every driver's X-macro table, regs.h), the board's pins
 * (pour/board_facts.h), and what the drivers write with the board's configuration (each driver run on a
 * register file in memory, each field of its table read back: "WRITE <block> <reg> <field> <value>"), in the
 * line form tests/board/check_registers.py compares with ST's description of the chip (the stm32g4 crate:
 * positions, and the meaning of each written value against tests/board/register_intents.txt) and ST's pin
 * database (the stm32-metapac crate). */
#define _POSIX_C_SOURCE 200112L /* clock_gettime under -std=c99 (clock_chip.h) */
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "adc_inj.h"
#include "clock.h"
#include "clock_chip.h"
#include "encoder_tim4.h"
#include "fdcan.h"
#include "flash_g4.h"
#include "gpio.h"
#include "hal_watchdog.h"
#include "iwdg.h"
#include "ocp.h"
#include "opamp.h"
#include "pour/board_facts.h"
#include "pwm_tim1.h"
#include "stm32g431_regs.h"

#define PRINT_PERIPH(inst, block, base) printf("PERIPH %s %s 0x%08lx\n", #inst, #block, (unsigned long)(base));
#define PRINT_REG(block, reg, offset) printf("REG %s %s 0x%03x\n", #block, #reg, (unsigned)(offset));
#define PRINT_FIELD(block, reg, field, pos, width)                                                             \
  printf("FIELD %s %s %s %u %u\n", #block, #reg, #field, (unsigned)(pos), (unsigned)(width));
#define PRINT_PIN(name, port, pin, owner, signal, af, use, parts, source)                                     \
  printf("PIN %s P%s%u %s %s %d\n", #name, #port, (unsigned)(pin), #owner, #signal, (int)(af));
#define PRINT_TABLE(X) POUR_##X##_PERIPHS(PRINT_PERIPH) POUR_##X##_REGS(PRINT_REG) POUR_##X##_FIELDS(PRINT_FIELD)

/* Each field of a driver's table as its register file holds it. */
#define PRINT_WRITE_AS(name, file, block, reg, field, pos, width)                                               \
  printf("WRITE %s %s %s %lu\n", name, #reg, #field,                                                          \
         (unsigned long)((file[POUR_##block##_##reg] >> (pos)) & (0xFFFFFFFFu >> (32u - (width)))));
#define PRINT_WRITE(file, block, reg, field, pos, width) PRINT_WRITE_AS(#block, file, block, reg, field, pos, width)
#define WRITE_OPAMP(block, reg, field, pos, width) PRINT_WRITE(opamp, block, reg, field, pos, width)
#define WRITE_TIM1(block, reg, field, pos, width) PRINT_WRITE(tim1, block, reg, field, pos, width)
#define WRITE_TIM4(block, reg, field, pos, width) PRINT_WRITE(tim4, block, reg, field, pos, width)
#define WRITE_COMP(block, reg, field, pos, width) PRINT_WRITE(comp, block, reg, field, pos, width)
#define WRITE_DAC(block, reg, field, pos, width) PRINT_WRITE(dac, block, reg, field, pos, width)
#define WRITE_OCP(block, reg, field, pos, width) WRITE_##block(block, reg, field, pos, width)

/* ADC1 and ADC2 by instance (their sequences differ); each converted channel's sample time (SMPR1: 0 .. 9,
 * SMPR2: 10 .. 18; the table's SMP0/SMP9/SMP10/SMP18 give the stride); JDR, ISR: data and flags. */
static volatile uint32_t adc1[POUR_ADC_N_REGS], adc2[POUR_ADC_N_REGS], adc12[POUR_ADC_N_REGS];
#define WRITE_ADC_ADC(reg, field, pos, width)                                                                 \
  if (strcmp(#reg, "SMPR1") != 0 && strcmp(#reg, "SMPR2") != 0) {                                            \
    PRINT_WRITE_AS("ADC1", adc1, ADC, reg, field, pos, width)                                                 \
    PRINT_WRITE_AS("ADC2", adc2, ADC, reg, field, pos, width)                                                 \
  }
#define WRITE_ADC_ADC12(reg, field, pos, width) PRINT_WRITE(adc12, ADC12, reg, field, pos, width)
#define WRITE_ADC(block, reg, field, pos, width) WRITE_ADC_##block(reg, field, pos, width)

static void print_sample_times(const char *name, const volatile uint32_t *r) {
  const uint32_t jsqr = r[POUR_ADC_JSQR];
  const unsigned ranks = (unsigned)POUR_GET(ADC, JSQR, JL, jsqr) + 1u;
  for (unsigned i = 0; i < ranks; ++i) {
    const unsigned ch = (unsigned)((jsqr >> (POUR_ADC_JSQR_JSQ1_POS + 6u * i)) & 0x1Fu);
    const unsigned shift = (unsigned)POUR_ADC_SMPR1_SMP0_WIDTH * (ch % 10u);
    const uint32_t smpr = ch < 10u ? r[POUR_ADC_SMPR1] : r[POUR_ADC_SMPR2];
    printf("WRITE %s %s SMP%u %lu\n", name, ch < 10u ? "SMPR1" : "SMPR2", ch, (unsigned long)((smpr >> shift) & 7u));
  }
}

/* The clock's blocks (clock.c): the registers it writes; the peripheral enables of AHB2ENR, APB2ENR,
 * APB1ENR1 and CCIPR.FDCANSEL are board_stm32g431.c's (not run on the host), FLASH.OPTR boot_check's (read). */
static volatile uint32_t rcc[0x100 / 4], pwr[0x100 / 4], flash[0x100 / 4], lptim[0x40 / 4], systick[0x10 / 4];
static volatile uint32_t iwdg[0x10 / 4];
static int clock_writes(const char *reg, const char *field) {
  static const char *const not_clock[] = {"AHB2ENR", "APB2ENR", "OPTR", "TIM4EN", "FDCANEN", "FDCANSEL"};
  for (unsigned i = 0; i < sizeof not_clock / sizeof not_clock[0]; ++i) {
    if (strcmp(reg, not_clock[i]) == 0 || strcmp(field, not_clock[i]) == 0) {
      return 0;
    }
  }
  return 1;
}
#define WRITE_CHIP_RCC(reg, field, pos, width)                                                                \
  if (clock_writes(#reg, #field)) {                                                                           \
    PRINT_WRITE(rcc, RCC, reg, field, pos, width)                                                             \
  }
#define WRITE_CHIP_PWR(reg, field, pos, width) PRINT_WRITE(pwr, PWR, reg, field, pos, width)
#define WRITE_CHIP_FLASH(reg, field, pos, width)                                                              \
  if (clock_writes(#reg, #field)) {                                                                           \
    PRINT_WRITE(flash, FLASH, reg, field, pos, width)                                                         \
  }
#define WRITE_CHIP_IWDG(reg, field, pos, width) PRINT_WRITE(iwdg, IWDG, reg, field, pos, width)
#define WRITE_CHIP_LPTIM(reg, field, pos, width) PRINT_WRITE(lptim, LPTIM, reg, field, pos, width)
#define WRITE_CHIP_GPIO(reg, field, pos, width) /* per pin: print_pins */
#define WRITE_CHIP(block, reg, field, pos, width) WRITE_CHIP_##block(reg, field, pos, width)

/* The GPIO ports, each pin set up as board_stm32g431.c does from the board's table: a GPIO OUT pin an output
 * driven to its level, a GPIO IN pin an input without pull, a pin with an alternate function that function,
 * any other (the converters' inputs and outputs) analog; TIM1's gate pins at high speed. BSRR's writes land in ODR, as on the chip. */
static volatile uint32_t gpio[3][0x400 / 4];
/* The outputs' levels at start-up (board_stm32g431.c): the brake engaged (low), the power stage off (low),
 * the LED off, the CAN transceiver awake (SHDN low) and terminated (CAN_TERMINATED). */
static int start_level(const char *name) { return strcmp(name, "CAN_TERM") == 0; }
static void fold_bsrr(volatile uint32_t *port) {
  const uint32_t bsrr = port[POUR_GPIO_BSRR];
  port[POUR_GPIO_ODR] = (port[POUR_GPIO_ODR] & ~(bsrr >> 16)) | (bsrr & 0xFFFFu);
  port[POUR_GPIO_BSRR] = 0u;
}
#define SET_PIN(name, port, pin, owner, signal, af, use, parts, source)                                       \
  setup_pin(#name, (unsigned)(POUR_BOARD_PIN_##name##_PORT), (unsigned)(pin), #owner, #signal, (int)(af));
/* The table's pins the port leaves at reset (the on-board parts it does not use: docs/bringup.md); the
 * register test checks this list against the pins board_stm32g431.c names. */
static int left_at_reset(const char *name) {
  static const char *const unused[] = {"POT", "BUTTON", "BEMF_U", "BEMF_V", "BEMF_W", "BEMF_EN", "VCP_RX"};
  for (unsigned i = 0; i < sizeof unused / sizeof unused[0]; ++i) {
    if (strcmp(name, unused[i]) == 0) {
      return 1;
    }
  }
  return 0;
}
static void setup_pin(const char *name, unsigned port, unsigned pin, const char *owner, const char *signal, int af) {
  const pour_gpio_t g = {gpio[port], (uint8_t)pin};
  if (left_at_reset(name)) {
    return;
  }
  if (strcmp(owner, "GPIO") == 0 && strcmp(signal, "OUT") == 0) {
    pour_gpio_output(g, start_level(name) != 0);
    fold_bsrr(gpio[port]);
  } else if (strcmp(owner, "GPIO") == 0) {
    pour_gpio_input(g, POUR_GPIO_PULL_NONE);
  } else if (af >= 0) {
    if (strcmp(owner, "TIM1") == 0) {
      pour_gpio_speed(g, POUR_GPIO_SPEED_HIGH);
    }
    pour_gpio_alternate(g, (uint32_t)af);
  } else {
    pour_gpio_analog(g);
  }
}
#define PRINT_PIN_WRITES(name, port, pin, owner, signal, af, use, parts, source)                              \
  print_pin(#name, #port, (unsigned)(POUR_BOARD_PIN_##name##_PORT), (unsigned)(pin), #owner, #signal, (int)(af));
static void print_pin(const char *name, const char *letter, unsigned port, unsigned pin, const char *owner,
                      const char *signal, int af) {
  const volatile uint32_t *r = gpio[port];
  if (left_at_reset(name)) {
    return;
  }
  printf("WRITE GPIO%s MODER MODER%u %lu\n", letter, pin, (unsigned long)((r[POUR_GPIO_MODER] >> (2u * pin)) & 3u));
  printf("WRITE GPIO%s PUPDR PUPDR%u %lu\n", letter, pin, (unsigned long)((r[POUR_GPIO_PUPDR] >> (2u * pin)) & 3u));
  if (strcmp(owner, "GPIO") == 0 && strcmp(signal, "OUT") == 0) {
    printf("WRITE GPIO%s OTYPER OT%u %lu\n", letter, pin, (unsigned long)((r[POUR_GPIO_OTYPER] >> pin) & 1u));
    printf("WRITE GPIO%s ODR ODR%u %lu\n", letter, pin, (unsigned long)((r[POUR_GPIO_ODR] >> pin) & 1u));
  } else if (af >= 0) {
    printf("WRITE GPIO%s OSPEEDR OSPEEDR%u %lu\n", letter, pin, (unsigned long)((r[POUR_GPIO_OSPEEDR] >> (2u * pin)) & 3u));
    const uint32_t afr = pin < 8u ? r[POUR_GPIO_AFRL] : r[POUR_GPIO_AFRH];
    printf("WRITE GPIO%s %s %s%u %lu\n", letter, pin < 8u ? "AFRL" : "AFRH", pin < 8u ? "AFRL" : "AFRH", pin,
           (unsigned long)((afr >> (4u * (pin % 8u))) & 15u));
  }
}

/* FDCAN1 as the board starts it: 170 MHz kernel clock (PCLK1), 1 Mbit/s. */
static volatile uint32_t fdcan[POUR_FDCAN_N_REGS], sramcan[POUR_FDCAN_RAM_WORDS];
#define WRITE_FDCAN(block, reg, field, pos, width) PRINT_WRITE(fdcan, block, reg, field, pos, width)

/* The chip's side while the drivers wait on it: the clock (clock_chip.h), and each ADC's calibration ending
 * and ADRDY once enabled (RM0440 §21.4.8, §21.4.9). */
static volatile int running;
static clock_chip_t clock_chip = {rcc, lptim, systick, 80u /* 8 MHz: pour/board_facts.h HSE_HZ */, 0u, 0u, 0u, 0u};
static void adc_step(volatile uint32_t *r) {
  const uint32_t cr = r[POUR_ADC_CR];
  if ((cr & POUR_MSK(ADC, CR, ADCAL)) != 0u) {
    r[POUR_ADC_CR] = cr & ~POUR_MSK(ADC, CR, ADCAL);
  } else if ((cr & POUR_MSK(ADC, CR, ADEN)) != 0u && (r[POUR_ADC_ISR] & POUR_MSK(ADC, ISR, ADRDY)) == 0u) {
    r[POUR_ADC_ISR] |= POUR_MSK(ADC, ISR, ADRDY);
  }
}
static void *chip(void *arg) {
  (void)arg;
  clock_chip_start(&clock_chip);
  while (running) {
    clock_chip_step(&clock_chip);
    adc_step(adc1);
    adc_step(adc2);
  }
  return NULL;
}

/* The drivers as the board configures them (board_stm32g431.c), on register files. */
static int print_writes(void) {
  static uint32_t opamp[POUR_OPAMP_N_REGS], tim1[POUR_TIM1_N_REGS], tim4[POUR_TIM4_N_REGS];
  static uint32_t comp[POUR_OCP_COMP_N_REGS], dac[POUR_OCP_DAC_N_REGS];
  const pour_pwm_config_t pc = pour_pwm_default_config();
  pour_pwm_t pwm;
  const pour_ocp_config_t oc = pour_ocp_default_config();
  pour_ocp_t ocp;
  const uint16_t offsets[3] = {POUR_BOARD_OFFSET_NOMINAL_COUNTS, POUR_BOARD_OFFSET_NOMINAL_COUNTS,
                               POUR_BOARD_OFFSET_NOMINAL_COUNTS};
  dac[POUR_DAC_SR] = POUR_MSK(DAC, SR, DAC1RDY) | POUR_MSK(DAC, SR, DAC2RDY); /* the DAC ready, as the chip's */
  if (pour_opamp_init(opamp, POUR_BOARD_PGA_GAIN) != POUR_OK || pour_pwm_init(&pwm, tim1, &pc) != POUR_OK ||
      pour_encoder_init(tim4, 6u, 0) != POUR_OK || pour_ocp_init(&ocp, comp, dac, &oc, offsets) != POUR_OK) {
    fprintf(stderr, "board_regtable: a driver refused the board's configuration\n");
    return 1;
  }
  /* The clock from the board's crystal and the ADCs, with a thread playing the chip. */
  rcc[POUR_RCC_CR] = POUR_MSK(RCC, CR, HSERDY) | POUR_MSK(RCC, CR, PLLRDY);
  rcc[POUR_RCC_CFGR] = POUR_VAL(RCC, CFGR, SW, 1u) | POUR_VAL(RCC, CFGR, SWS, 1u); /* reset: HSI16 */
  pwr[POUR_PWR_CR5] = POUR_MSK(PWR, CR5, R1MODE);                                   /* reset: range 1 normal */
  pour_clock_config_t cc = pour_clock_default_config();
  cc.ready_polls = 500000000u; /* the crystal's timing takes 80 ms of the host's time */
  const pour_clock_hw_t hw = {rcc, pwr, flash, lptim, systick};
  uint32_t hz = 0u, crystal = 0u;
  pour_clock_source_t source;
  pour_adc_t adc;
  pthread_t thread;
  running = 1;
  if (pthread_create(&thread, NULL, chip, NULL) != 0) {
    fprintf(stderr, "board_regtable: no thread to play the chip\n");
    return 1;
  }
  const pour_status_t clock_status = pour_clock_setup(&hw, &cc, &hz, &source, &crystal);
  const pour_status_t adc_status = pour_adc_init(&adc, adc1, adc2, adc12, 100000000u, 0u);
  running = 0;
  pthread_join(thread, NULL);
  if (clock_status != POUR_OK || source != POUR_CLOCK_HSE || crystal != POUR_BOARD_HSE_HZ || adc_status != POUR_OK) {
    fprintf(stderr, "board_regtable: the clock or the ADCs refused the board's configuration\n");
    return 1;
  }
  POUR_BOARD_PINS(SET_PIN)
  pour_fdcan_config_t fc = pour_fdcan_default_config();
  fc.kernel_clock_hz = hz;
  pour_fdcan_t can;
  const pour_fdcan_hw_t can_hw = {fdcan, sramcan};
  if (pour_iwdg_set(iwdg, POUR_WATCHDOG_TIMEOUT_MS, 10u) != POUR_OK || pour_fdcan_init(&can, can_hw, &fc) != POUR_OK) {
    fprintf(stderr, "board_regtable: the watchdog or FDCAN refused the board's configuration\n");
    return 1;
  }
  POUR_OPAMP_FIELDS(WRITE_OPAMP)
  POUR_TIM1_FIELDS(WRITE_TIM1)
  POUR_TIM4_FIELDS(WRITE_TIM4)
  POUR_OCP_FIELDS(WRITE_OCP)
  POUR_ADC_FIELDS(WRITE_ADC)
  print_sample_times("ADC1", adc1);
  print_sample_times("ADC2", adc2);
  POUR_CHIP_FIELDS(WRITE_CHIP)
  POUR_BOARD_PINS(PRINT_PIN_WRITES)
  POUR_FDCAN_FIELDS(WRITE_FDCAN)
  return 0;
}

int main(void) {
  PRINT_TABLE(CHIP)
  PRINT_TABLE(FDCAN)
  PRINT_TABLE(TIM1)
  PRINT_TABLE(ADC)
  PRINT_TABLE(OPAMP)
  PRINT_TABLE(OCP)
  PRINT_TABLE(TIM4)
  PRINT_TABLE(FLASH)
  POUR_BOARD_PINS(PRINT_PIN)
  return print_writes();
}
