/* SPDX-License-Identifier: MIT */
/* Prints the Cortex-M4 port's register tables (every driver's X-macro table, regs.h), the board's pins
 * (pour/board_facts.h), and what the drivers write with the board's configuration (each driver run on a
 * register file in memory, each field of its table read back: "WRITE <block> <reg> <field> <value>"), in the
 * line form tests/board/check_registers.py compares with ST's description of the chip (the stm32g4 crate:
 * positions, and the meaning of each written value against tests/board/register_intents.txt) and ST's pin
 * database (the stm32-metapac crate). */
#include <stdio.h>
#include <string.h>

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

/* Each field of a driver's table as its register file holds it. */
#define PRINT_WRITE(file, block, reg, field, pos, width)                                                       \
  printf("WRITE %s %s %s %lu\n", #block, #reg, #field,                                                       \
         (unsigned long)((file[POUR_##block##_##reg] >> (pos)) & (0xFFFFFFFFu >> (32u - (width)))));
#define WRITE_OPAMP(block, reg, field, pos, width) PRINT_WRITE(opamp, block, reg, field, pos, width)
#define WRITE_TIM1(block, reg, field, pos, width) PRINT_WRITE(tim1, block, reg, field, pos, width)
#define WRITE_TIM4(block, reg, field, pos, width) PRINT_WRITE(tim4, block, reg, field, pos, width)
#define WRITE_COMP(block, reg, field, pos, width) PRINT_WRITE(comp, block, reg, field, pos, width)
#define WRITE_DAC(block, reg, field, pos, width) PRINT_WRITE(dac, block, reg, field, pos, width)
#define WRITE_OCP(block, reg, field, pos, width) WRITE_##block(block, reg, field, pos, width)

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
  POUR_OPAMP_FIELDS(WRITE_OPAMP)
  POUR_TIM1_FIELDS(WRITE_TIM1)
  POUR_TIM4_FIELDS(WRITE_TIM4)
  POUR_OCP_FIELDS(WRITE_OCP)
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
