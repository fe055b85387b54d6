// SPDX-License-Identifier: MIT
// Register values the tests write, each from RM0440's field descriptions (not from the firmware's driver).
#ifndef POUR_TEST_VB_ANALOG_SETUP_HPP
#define POUR_TEST_VB_ANALOG_SETUP_HPP

#include "harness.hpp"

namespace vbt {

// TIM1 offsets (RM0440 28.6.29)
enum : uint32_t { T1_CR1 = 0x00, T1_CR2 = 0x04, T1_DIER = 0x0C, T1_SR = 0x10, T1_EGR = 0x14, T1_CCMR1 = 0x18,
                  T1_CCMR2 = 0x1C, T1_CCER = 0x20, T1_CNT = 0x24, T1_ARR = 0x2C, T1_CCR1 = 0x34, T1_CCR2 = 0x38,
                  T1_CCR3 = 0x3C, T1_CCR4 = 0x40, T1_BDTR = 0x44, T1_AF1 = 0x60 };
// ADC offsets (RM0440 21.7)
enum : uint32_t { A_ISR = 0x00, A_IER = 0x04, A_CR = 0x08, A_CFGR = 0x0C, A_SMPR1 = 0x14, A_SMPR2 = 0x18,
                  A_JSQR = 0x4C, A_JDR1 = 0x80, C_CCR = 0x08 };

constexpr uint32_t ARR_20KHZ = 4250;  // 170 MHz / (2 x 20 kHz), centre-aligned

// TIM1 centre-aligned mode 1, ARPE, PWM mode 1 with preload on CH1..4, TRGO2 = OC4REF (MMS2 0111),
// CCR4 one tick below the top, the bridge's six outputs enabled under MOE; CEN last.
inline void tim1_pwm(Board& b, uint32_t ccr1, uint32_t ccr2, uint32_t ccr3, bool outputs = true) {
  b.w("TIM1", T1_CR1, (1u << 5) | (1u << 7));
  b.w("TIM1", T1_ARR, ARR_20KHZ);
  b.w("TIM1", T1_CCR1, ccr1);
  b.w("TIM1", T1_CCR2, ccr2);
  b.w("TIM1", T1_CCR3, ccr3);
  b.w("TIM1", T1_CCR4, ARR_20KHZ - 1u);
  b.w("TIM1", T1_CCMR1, (6u << 4) | (1u << 3) | (6u << 12) | (1u << 11));
  b.w("TIM1", T1_CCMR2, (6u << 4) | (1u << 3) | (6u << 12) | (1u << 11));
  b.w("TIM1", T1_CR2, 7u << 20);
  b.w("TIM1", T1_CCER, outputs ? 0x555u : 0u);  // CC1E CC1NE CC2E CC2NE CC3E CC3NE
  b.w("TIM1", T1_BDTR, 0x84u | (1u << 10) | (1u << 11) | (1u << 15));  // DTG 0x84: (64 + 4) x 2 = 136 ticks = 800 ns, OSSI, OSSR, MOE
  b.w("TIM1", T1_EGR, 1u);
  b.w("TIM1", T1_SR, 0u);
  b.w("TIM1", T1_CR1, (1u << 5) | (1u << 7) | 1u);
}

// ADC bring-up as RM0440 21.4.6 .. 21.4.9 orders it: leave deep power-down, the regulator, tADCVREG_STUP,
// calibration, ADEN, ADRDY.
inline void adc_up(Board& b, const std::string& adc) {
  b.w(adc, A_CR, 0u);
  b.w(adc, A_CR, 1u << 28);
  b.run_s(25e-6);
  b.w(adc, A_CR, (1u << 28) | (1u << 31));
  b.run_s(20e-6);
  b.w(adc, A_CR, 1u << 28);  // the rs bits: writing 0 leaves ADCAL to the hardware
  b.w(adc, A_ISR, 1u);
  b.w(adc, A_CR, (1u << 28) | 1u);
  b.run_s(5e-6);
}

// JSQR: JL = n-1, JEXTSEL 8 (TIM1_TRGO2, RM0440 table 163), JEXTEN rising, the channels.
inline uint32_t jsqr(uint32_t n, uint32_t c1, uint32_t c2 = 0, uint32_t c3 = 0, uint32_t c4 = 0) {
  return (n - 1u) | (8u << 2) | (1u << 7) | (c1 << 9) | (c2 << 15) | (c3 << 21) | (c4 << 27);
}

// OPAMPx_CSR: OPAEN, VP_SEL VINP0, VM_SEL PGA (10), PGA_GAIN 01011 (x16, gain network's foot on VINM0).
constexpr uint32_t OPAMP_PGA16 = 1u | (2u << 5) | (0x0Bu << 14);

}  // namespace vbt

#endif
