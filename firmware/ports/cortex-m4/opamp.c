/* SPDX-License-Identifier: MIT */
#include "opamp.h"

#include <stddef.h>

#define VM_SEL_VINM0 0u /* inverting input on its pin: the board's feedback network */
#define VM_SEL_PGA 2u   /* inverting input to the internal gain network */
#define VP_SEL_VINP0 0u

pour_status_t pour_opamp_init(volatile uint32_t *regs, uint32_t gain) {
  uint32_t code = 0u; /* PGA_GAIN 0..5: gain 2 << code, non-inverting, no external filter (RM0440) */
  while (code < 6u && (2u << code) != gain) {
    ++code;
  }
  if (regs == NULL || (code == 6u && gain != 0u)) {
    return POUR_EINVAL;
  }
  const uint32_t vm = gain == 0u ? POUR_VAL(OPAMP, OPAMP1_CSR, VM_SEL, VM_SEL_VINM0)
                                 : POUR_VAL(OPAMP, OPAMP1_CSR, VM_SEL, VM_SEL_PGA) | POUR_VAL(OPAMP, OPAMP1_CSR, PGA_GAIN, code);
  const uint32_t csr = POUR_MSK(OPAMP, OPAMP1_CSR, OPAEN) | POUR_VAL(OPAMP, OPAMP1_CSR, VP_SEL, VP_SEL_VINP0) | vm |
                       POUR_MSK(OPAMP, OPAMP1_CSR, OPAHSM);
  regs[POUR_OPAMP_OPAMP1_CSR] = csr; /* OPAINTOEN clear: output on the pin, where the ADC reads it */
  regs[POUR_OPAMP_OPAMP2_CSR] = csr;
  regs[POUR_OPAMP_OPAMP3_CSR] = csr;
  return POUR_OK;
}
