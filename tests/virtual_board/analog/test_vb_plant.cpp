// SPDX-License-Identifier: MIT
// The plant closing through the models: TIM1's duties x the bus drive host_sim's motor model; at stall a
// fixed duty pattern gives the current V / R (the leg voltages less the dead time's share), which the
// converter reads back through the shunt, the PGA and ADC1; a voltage vector 90 electrical degrees ahead
// of the rotor (the angle from TIM4's count) spins it forward, 90 behind spins it backward; seeded runs
// repeat exactly.
#include "setup.hpp"

using namespace vbt;

namespace {
constexpr double kPi = 3.14159265358979;

void compares(Board& b, const double d[3]) {
  b.w("TIM1", T1_CCR1, static_cast<uint32_t>(std::lround(d[0] * ARR_20KHZ)));
  b.w("TIM1", T1_CCR2, static_cast<uint32_t>(std::lround(d[1] * ARR_20KHZ)));
  b.w("TIM1", T1_CCR3, static_cast<uint32_t>(std::lround(d[2] * ARR_20KHZ)));
}

// Spin for `seconds` with the vector `lead` electrical radians ahead of the rotor; the motor's final speed.
double spin(double lead, double seconds, int32_t* counts, uint64_t seed = 1) {
  vb::AnalogOptions o;
  o.seed = seed;
  Board b(o);
  b.w("TIM4", 0x08, 3u);
  b.w("TIM4", 0x18, 1u | (1u << 8));
  b.w("TIM4", 0x00, 1u);
  tim1_pwm(b, ARR_20KHZ / 2, ARR_20KHZ / 2, ARR_20KHZ / 2);
  const int cpr = b.set.plant->encoder_cpr(), pp = b.set.plant->pole_pairs();
  const int periods = static_cast<int>(seconds * 20000.0);
  int32_t total = 0;
  uint16_t last = 0;
  for (int n = 0; n < periods; ++n) {
    const uint16_t c = static_cast<uint16_t>(b.r("TIM4", 0x24));
    total += static_cast<int16_t>(static_cast<uint16_t>(c - last));
    last = c;
    const double th = 2.0 * kPi * static_cast<double>(total) / cpr * pp + lead;
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = 0.5 + 0.08 * std::cos(th - 2.0 * kPi * k / 3.0);
    compares(b, d);
    b.run_s(50e-6);
  }
  *counts = total;
  return b.set.plant->omega();
}
}  // namespace

int main() {
  {  // Stall: U at 0.5 + a, V and W at 0.5 - a / 2: U's line-to-neutral voltage is a x Vbus less the dead
     // time's 4/3 x td x f x Vbus (U's current out of its leg, V's and W's in): I_U = that / R.
    vb::AnalogOptions o;
    o.locked_rotor = true;
    o.adc_noise_counts = 0.0;
    Board b(o);
    b.w("ADC12_COMMON", C_CCR, 3u << 16);
    b.w("OPAMP", 0x00, OPAMP_PGA16);
    adc_up(b, "ADC1");
    b.w("ADC1", A_SMPR1, 1u << 9);
    b.w("ADC1", A_JSQR, jsqr(1, 3));
    b.w("ADC1", A_CR, (1u << 28) | 1u | (1u << 3));
    const double a = 0.1;
    const double d[3] = {0.5 + a, 0.5 - a / 2, 0.5 - a / 2};
    tim1_pwm(b, 0, 0, 0);
    compares(b, d);
    b.run_s(20e-3);
    const double vb = b.set.plant->vbus(), r = b.set.plant->r_phase();
    const double duty_err = b.set.plant->deadtime_s() * 20000.0;
    const double expect = static_cast<double>(std::lround(d[0] * ARR_20KHZ) - std::lround(d[1] * ARR_20KHZ)) / static_cast<double>(ARR_20KHZ) *
                              (2.0 / 3.0) * vb / r -
                          (4.0 / 3.0) * duty_err * vb / r;
    const double i = b.set.plant->phase_current(0);
    CHECK(std::fabs(i - expect) < 0.03 * std::fabs(expect), "stall current %.3f A, V/R %.3f A", i, expect);
    CHECK(std::fabs(b.set.plant->omega()) == 0.0, "locked");
    // Read back: I = (bias - code) x 3.3 / 4096 / (16 x 0.571 x 0.003), bias 2553 counts (2.057 V).
    const double code = b.r("ADC1", A_JDR1);
    const double i_adc = (2553.0 - code) * 3.3 / 4096.0 / (16.0 * 0.571 * 0.003);
    CHECK(std::fabs(i_adc - i) < 0.03 * std::fabs(i), "ADC reads %.3f A of %.3f A (code %.0f)", i_adc, i, code);
    std::printf("stall: I_U %.3f A, V/R %.3f A (%.2f %%), ADC1 JDR1 %.0f -> %.3f A, Vbus %.3f V, R %.4f Ohm\n", i, expect,
                100.0 * (i - expect) / expect, code, i_adc, vb, r);
  }
  {
    int32_t fwd = 0, back = 0;
    const double w_fwd = spin(kPi / 2, 0.2, &fwd);
    const double w_back = spin(-kPi / 2, 0.2, &back);
    CHECK(w_fwd > 50.0 && fwd > 0, "90 degrees ahead spins forward: %.1f rad/s, %d counts", w_fwd, fwd);
    CHECK(w_back < -50.0 && back < 0, "90 degrees behind spins backward: %.1f rad/s, %d counts", w_back, back);
    std::printf("spin 0.2 s: forward %.1f rad/s (%d counts), backward %.1f rad/s (%d counts)\n", w_fwd, fwd, w_back, back);
    int32_t again = 0;
    const double w_again = spin(kPi / 2, 0.2, &again);
    CHECK(w_again == w_fwd && again == fwd, "the same seed repeats exactly");
  }
  {  // A load from outside (host_sim's bucket, for the board): with the bridge off it turns the shaft back.
    Board b;
    b.set.plant->set_load([](double, double, double) { return 0.02; });
    tim1_pwm(b, 0, 0, 0, false);
    b.run_s(20e-3);
    CHECK(b.set.plant->omega() < -1.0, "the load drives the shaft backward: %.2f rad/s", b.set.plant->omega());
  }
  {  // Encoder stuck: the count stops while the rotor turns.
    vb::AnalogOptions o;
    o.fault_encoder_stuck = true;
    o.fault_at_s = 0.0;
    Board b(o);
    b.w("TIM4", 0x08, 3u);
    b.w("TIM4", 0x18, 1u | (1u << 8));
    b.w("TIM4", 0x00, 1u);
    tim1_pwm(b, 0, 0, 0);
    const double d[3] = {0.5, 0.5866, 0.4134};  // a vector 90 electrical degrees from the rotor at rest
    compares(b, d);
    b.run_s(20e-3);
    CHECK(std::fabs(b.set.plant->theta()) > 0.01, "the rotor moved: %.3f rad", b.set.plant->theta());
    CHECK(b.r("TIM4", 0x24) == 0u, "stuck encoder: count stays 0, got %u", b.r("TIM4", 0x24));
  }
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
