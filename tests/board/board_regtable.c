/* SPDX-License-Identifier: MIT */
/* Prints the Cortex-M4 port's register tables (every driver's X-macro table, regs.h) and the board's pins
 * (pour/board_facts.h) in the line form tests/board/check_registers.py compares with ST's description of the
 * chip (the stm32g4 crate) and ST's pin database (the stm32-metapac crate). */
#include <stdio.h>

#include "adc_inj.h"
#include "encoder_tim4.h"
#include "fdcan.h"
#include "flash_g4.h"
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
  return 0;
}
