// SPDX-License-Identifier: MIT
// ADC1 / ADC2 against RM0440 section 21: the reset values, the power-up order (ADEN before the regulator is
// ready, or during calibration, stops the board by name), an injected sequence on TIM1's TRGO2 with JEOC /
// JEOS, its interrupt and its timing, and a known phase current through the board's chain to a code.
#include "setup.hpp"

using namespace vbt;

namespace {
bool any_stop_contains(const Board& b, const char* what) {
  for (const auto& s : b.link.stops) if (s.find(what) != std::string::npos) return true;
  return false;
}
}  // namespace

int main() {
  {
    Board b;
    CHECK(b.r("ADC1", A_CR) == 0x20000000u, "CR reset: DEEPPWD");
    CHECK(b.r("ADC1", A_CFGR) == 0x80000000u, "CFGR reset: JQDIS");
    CHECK(b.r("ADC2", 0x20) == 0x0FFF0000u, "TR1 reset");
  }
  {  // ADEN right after ADVREGEN: the regulator needs tADCVREG_STUP (20 us) first.
    Board b;
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    b.w("ADC1", A_CR, 0u);
    b.w("ADC1", A_CR, 1u << 28);
    b.run_s(5e-6);
    b.w("ADC1", A_CR, (1u << 28) | 1u);
    CHECK(any_stop_contains(b, "ADC1: ADEN set before the voltage regulator is ready"), "stops: %s",
          b.link.stops.empty() ? "(none)" : b.link.stops[0].c_str());
    CHECK((b.r("ADC1", A_CR) & 1u) == 0u, "ADEN stays clear");
  }
  {  // ADEN during calibration
    Board b;
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    b.w("ADC1", A_CR, 0u);
    b.w("ADC1", A_CR, 1u << 28);
    b.run_s(25e-6);
    b.w("ADC1", A_CR, (1u << 28) | (1u << 31));
    b.w("ADC1", A_CR, (1u << 28) | 1u);
    CHECK(any_stop_contains(b, "ADEN set during calibration"), "stops: %s",
          b.link.stops.empty() ? "(none)" : b.link.stops[0].c_str());
  }
  {  // JADSTART before ADRDY: the ADC is still starting (tSTAB)
    Board b;
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    b.w("ADC1", A_CR, 0u);
    b.w("ADC1", A_CR, 1u << 28);
    b.run_s(25e-6);
    b.w("ADC1", A_CR, (1u << 28) | (1u << 31));
    b.run_s(20e-6);
    b.w("ADC1", A_CR, (1u << 28) | 1u);
    b.w("ADC1", A_CR, (1u << 28) | 1u | (1u << 3));
    CHECK(any_stop_contains(b, "JADSTART set before the ADC is ready"), "stops: %s",
          b.link.stops.empty() ? "(none)" : b.link.stops[0].c_str());
  }
  {  // ADVREGEN in deep power-down
    Board b;
    b.w("ADC2", A_CR, (1u << 29) | (1u << 28));
    CHECK(any_stop_contains(b, "deep power-down"), "ADVREGEN with DEEPPWD stops");
  }
  {  // The proper order: no stop, ADCAL clears after 116 ADC clocks, ADRDY.
    Board b;
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    adc_up(b, "ADC1");
    CHECK(b.link.stops.empty(), "no stop: %s", b.link.stops.empty() ? "" : b.link.stops[0].c_str());
    CHECK((b.r("ADC1", A_ISR) & 1u) != 0u, "ADRDY");
    CHECK((b.r("ADC1", A_CR) & (1u << 31)) == 0u, "ADCAL done");
  }
  {  // An injected conversion of a known phase current: locked rotor, the low sides on (CCR = 0), phase U
     // carrying +10 A into the motor (the fault option), ADC1 IN3 = OPAMP1 VOUT (PA2) in PGA x16.
     // The board as UM2516 / ST's MCSDK describe it: R = 3 mOhm, network 0.571, bias at VINP 0.1285625 V:
     //   VINP = 0.1285625 - 0.571 x 0.003 x 10 = 0.1114325 V; VOUT = 16 x VINP = 1.78292 V;
     //   code = 1.78292 x 4096 / 3.3 = 2212.97 -> 2213.
    vb::AnalogOptions o;
    o.adc_noise_counts = 0.0;
    o.locked_rotor = true;
    o.fault_phase_overcurrent_a = 10.0;
    Board b(o);
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    b.w("OPAMP", 0x00, OPAMP_PGA16);
    b.w("OPAMP", 0x04, OPAMP_PGA16);
    adc_up(b, "ADC1");
    b.w("ADC1", A_SMPR1, 1u << 9);  // IN3: SMP 001, 6.5 cycles
    b.w("ADC1", A_JSQR, jsqr(2, 3, 11));
    b.w("ADC1", A_IER, 1u << 6);    // JEOSIE
    b.w("ADC1", A_CR, (1u << 28) | 1u | (1u << 3));
    CHECK(b.link.stops.empty(), "no stop: %s", b.link.stops.empty() ? "" : b.link.stops[0].c_str());
    tim1_pwm(b, 0, 0, 0);
    const uint64_t t0 = b.link.now;
    // TRGO2 at t0 + 4251; + 3 ADC clocks latency; IN3: (6.5 + 12.5) x 4 = 76 cycles.
    b.run_to(t0 + ARR_20KHZ + 1u + 12u + 75u);
    CHECK((b.r("ADC1", A_ISR) & (1u << 5)) == 0u, "no JEOC one cycle early");
    b.run_to(t0 + ARR_20KHZ + 1u + 12u + 76u);
    CHECK((b.r("ADC1", A_ISR) & (1u << 5)) != 0u, "JEOC at the first rank's end");
    CHECK((b.r("ADC1", A_ISR) & (1u << 6)) == 0u, "JEOS waits for rank 2");
    b.run_to(t0 + 2u * ARR_20KHZ);
    CHECK((b.r("ADC1", A_ISR) & (1u << 6)) != 0u, "JEOS");
    CHECK(b.link.irq[vb::IRQ_ADC1_2], "ADC1_2 line (table 97 position 18) high");
    const uint32_t code = b.r("ADC1", A_JDR1);
    CHECK(code == 2213u, "JDR1 of +10 A into phase U: %u (expected 2213)", code);
    const uint32_t pot = b.r("ADC1", A_JDR1 + 4);
    CHECK(pot == 2048u, "JDR2: the potentiometer at half of 3.3 V: %u", pot);
    b.w("ADC1", A_ISR, (1u << 5) | (1u << 6));
    CHECK(!b.link.irq[vb::IRQ_ADC1_2], "the line falls once JEOS is cleared");
  }
  {  // ADC2 IN3 = OPAMP2 VOUT (PA6): zero current gives the bias, 16 x 0.1285625 V = 2.057 V -> 2553.
    vb::AnalogOptions o;
    o.adc_noise_counts = 0.0;
    o.locked_rotor = true;
    Board b(o);
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    b.w("OPAMP", 0x04, OPAMP_PGA16);
    adc_up(b, "ADC2");
    b.w("ADC2", A_JSQR, jsqr(1, 3));
    b.w("ADC2", A_CR, (1u << 28) | 1u | (1u << 3));
    tim1_pwm(b, 0, 0, 0);
    b.run_s(60e-6);
    const uint32_t code = b.r("ADC2", A_JDR1);
    CHECK(code == 2553u, "ADC2 JDR1 at zero current: %u (expected 2553)", code);
    b.w("ADC2", A_SMPR1, 0u);
    CHECK(any_stop_contains(b, "SMPR written during a conversion"), "SMPR with JADSTART stops");
  }
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
