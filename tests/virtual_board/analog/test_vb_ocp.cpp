// SPDX-License-Identifier: MIT
// The over-current trip: DAC3's threshold on COMP1's INM, the shunt network on its INP (PA1), its output
// into TIM1's break (AF1 BKCMP1E, BKE, BKP): a phase current past the threshold clears MOE and sets BIF with
// no write from software; one below it does not. Also DAC3's and COMP's reset values and ready flag.
#include "setup.hpp"

using namespace vbt;

namespace {
// DAC3 channel 1 internal (MODE 011), the threshold code, EN1; COMP1: EN, INMSEL 100 (DAC3 CH1), HYST 10 mV.
void arm(Board& b, uint32_t code) {
  b.w("DAC3", 0x3C, 3u);
  b.w("DAC3", 0x08, code);
  b.w("DAC3", 0x00, 1u);
  b.run_s(10e-6);
  b.w("COMP", 0x00, 1u | (4u << 4) | (1u << 16));
  b.w("TIM1", T1_AF1, 1u | (1u << 1));
}
}  // namespace

int main() {
  {
    Board b;
    CHECK(b.r("DAC3", 0x48) == 0x00010001u && b.r("DAC3", 0x4C) == 0x00010001u, "SHHR, SHRR reset");
    CHECK(b.r("COMP", 0x00) == 0u, "C1CSR reset");
    b.w("DAC3", 0x3C, 3u);
    b.w("DAC3", 0x00, 1u);
    CHECK((b.r("DAC3", 0x34) & (1u << 11)) == 0u, "DAC1RDY not at once");
    b.run_s(10e-6);
    CHECK((b.r("DAC3", 0x34) & (1u << 11)) != 0u, "DAC1RDY after the wake-up");
    b.w("DAC3", 0x3C, 0u);
    CHECK(!b.link.stops.empty(), "MODE1 written with EN1 set stops the board");
  }
  {  // RM0440 22.7.15 DAC_MCR HFSEL: above 160 MHz of AHB clock it must be 10. Strict, the board stops.
    vb::AnalogOptions o;
    o.strict_dac_hfsel = true;
    Board b(o);
    b.w("DAC3", 0x3C, 3u);
    b.w("DAC3", 0x00, 1u);
    CHECK(!b.link.stops.empty() && b.link.stops[0].find("HFSEL = 0") != std::string::npos,
          "EN1 at 170 MHz with HFSEL 0 stops: %s", b.link.stops.empty() ? "(none)" : b.link.stops[0].c_str());
    Board ok(o);
    ok.w("DAC3", 0x3C, 3u | (2u << 14));
    ok.w("DAC3", 0x00, 1u);
    CHECK(ok.link.stops.empty(), "HFSEL 10: no stop");
  }
  // Threshold for 40 A out of the phase into the low side (the shunt's positive voltage):
  //   0.1285625 + 0.571 x 0.003 x 40 = 0.1970825 V -> x 4096 / 3.3 = 244.6 -> 245.
  const uint32_t thr = 245;
  for (double amps : {-50.0, -30.0}) {
    vb::AnalogOptions o;
    o.adc_noise_counts = 0.0;
    o.locked_rotor = true;
    o.fault_phase_overcurrent_a = amps;  // into the motor: negative = out of the phase, through the shunt
    o.fault_at_s = 200e-6;
    Board b(o);
    tim1_pwm(b, 0, 0, 0);
    b.w("TIM1", T1_DIER, 1u << 7);  // BIE
    arm(b, thr);
    b.w("TIM1", T1_BDTR, 0x84u | (1u << 10) | (1u << 11) | (1u << 12) | (1u << 13) | (1u << 15));
    CHECK((b.r("TIM1", T1_BDTR) & (1u << 15)) != 0u, "MOE set before the fault");
    b.run_s(150e-6);
    CHECK((b.r("TIM1", T1_SR) & (1u << 7)) == 0u, "no break before the fault");
    b.run_s(200e-6);  // no register is written from here on
    const bool tripped = (b.r("TIM1", T1_SR) & (1u << 7)) != 0u;
    if (amps < -40.0) {
      CHECK(tripped, "%.0f A trips: BIF", amps);
      CHECK((b.r("TIM1", T1_BDTR) & (1u << 15)) == 0u, "MOE cleared by the hardware");
      CHECK(!b.set.tim1->outputs_enabled(), "the bridge's outputs at their idle levels (off)");
      CHECK(b.link.rises[vb::IRQ_TIM1_BRK] == 1, "TIM1_BRK line (position 24) rose once");
      CHECK(!b.set.tim1->low_side_on(0), "idle: OIS1N = 0, the low side off too");
    } else {
      CHECK(!tripped, "%.0f A stays below the 40 A threshold", amps);
      CHECK((b.r("TIM1", T1_BDTR) & (1u << 15)) != 0u, "MOE stays");
    }
  }
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
