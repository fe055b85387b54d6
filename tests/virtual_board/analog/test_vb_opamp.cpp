// SPDX-License-Identifier: MIT
// OPAMP1..3 against RM0440 section 25: reset, the output following the configured mode (PGA x16 on the
// shunt network's bias, follower, open loop saturating to a rail, disabled giving nothing), and the ADC
// reading an op-amp left open loop at full scale.
#include "setup.hpp"

using namespace vbt;

int main() {
  vb::AnalogOptions o;
  o.adc_noise_counts = 0.0;
  o.locked_rotor = true;
  Board b(o);
  CHECK(b.r("OPAMP", 0x00) == 0u && b.r("OPAMP", 0x08) == 0u, "CSR reset 0");
  uint32_t v = 0;
  CHECK(!b.set.opamp->read(0x0C, 4, &v), "OPAMP4 is not on the STM32G431: refused");
  // The windows of RM0440 table 4 (bases as in the stm32g4 crate): COMP and OPAMP 256 bytes each, adjacent.
  CHECK(b.set.comp->base() == 0x40010200u && b.set.comp->base() + b.set.comp->size() == b.set.opamp->base(),
        "COMP's window ends where OPAMP's begins");
  double out = 0.0;
  CHECK(!b.set.opamp->output(0, &out), "disabled: no output");
  b.w("OPAMP", 0x00, OPAMP_PGA16);
  // VINP0 at zero current: 0.1285625 V (ST's MCSDK WB_UI_VPOL_K); x16 = 2.057 V (WB_UI_VPOL).
  CHECK(b.set.opamp->output(0, &out) && std::fabs(out - 2.057) < 1e-3, "PGA x16: %.4f V", out);
  b.w("OPAMP", 0x00, 1u | (3u << 5));  // follower
  CHECK(b.set.opamp->output(0, &out) && std::fabs(out - 0.1285625) < 1e-5, "follower: %.5f V", out);
  b.w("OPAMP", 0x00, 1u | (2u << 5) | (0x01u << 14));  // PGA x4, foot grounded internally
  CHECK(b.set.opamp->output(0, &out) && std::fabs(out - 4 * 0.1285625) < 1e-5, "PGA x4: %.5f V", out);
  // Open loop: VM_SEL = VINM0 with no feedback: VINP (0.13 V) above VINM0 (0 V) drives it to VDDA.
  b.w("OPAMP", 0x00, 1u | (0u << 5));
  CHECK(b.set.opamp->output(0, &out) && std::fabs(out - 3.3) < 1e-9, "open loop saturates at the rail: %.3f V", out);
  // ... and the converter sees full scale: the wrong configuration is visible on the first sample.
  b.w("ADC12_COMMON", C_CCR, 3u << 16);
  adc_up(b, "ADC1");
  b.w("ADC1", A_JSQR, jsqr(1, 3));
  b.w("ADC1", A_CR, (1u << 28) | 1u | (1u << 3));
  tim1_pwm(b, 0, 0, 0);
  b.run_s(60e-6);
  CHECK(b.r("ADC1", A_JDR1) == 4095u, "open loop reads 4095: %u", b.r("ADC1", A_JDR1));
  // Disabled: nothing drives PA2 (code 0 here).
  b.w("OPAMP", 0x00, 0u);
  b.run_s(50e-6);
  CHECK(b.r("ADC1", A_JDR1) == 0u, "disabled op-amp reads 0: %u", b.r("ADC1", A_JDR1));
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
