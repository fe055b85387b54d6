/* SPDX-License-Identifier: MIT */
#include "opamp.h"

#include <stddef.h>

#define VM_SEL_PGA 2u   /* inverting input to the internal gain network (PGA mode) */
#define VP_SEL_VINP0 0u
#define PGA_BIAS_VINM0 8u /* PGA_GAIN 0b01xxx: the gain network's foot on VINM0 (input/bias there), RM0440 */

pour_status_t pour_opamp_init(volatile uint32_t *regs, uint32_t gain) {
  uint32_t code = 0u; /* PGA_GAIN[2:0] 0..5: gain 2 << code */
  while (code < 6u && (2u << code) != gain) {
    ++code;
  }
  if (regs == NULL || code == 6u) {
    return POUR_EINVAL;
  }
  const uint32_t csr = POUR_MSK(OPAMP, OPAMP1_CSR, OPAEN) | POUR_VAL(OPAMP, OPAMP1_CSR, VP_SEL, VP_SEL_VINP0) |
                       POUR_VAL(OPAMP, OPAMP1_CSR, VM_SEL, VM_SEL_PGA) |
                       POUR_VAL(OPAMP, OPAMP1_CSR, PGA_GAIN, PGA_BIAS_VINM0 | code) | POUR_MSK(OPAMP, OPAMP1_CSR, OPAHSM);
  regs[POUR_OPAMP_OPAMP1_CSR] = csr; /* OPAINTOEN clear: output on the pin, where the ADC reads it */
  regs[POUR_OPAMP_OPAMP2_CSR] = csr;
  regs[POUR_OPAMP_OPAMP3_CSR] = csr;
  return POUR_OK;
}
