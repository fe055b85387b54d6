// SPDX-License-Identifier: MIT
// The motor, inverter and bus model (motor_model.hpp).
#include "motor_model.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

namespace {
constexpr double kTwoPi = 6.283185307179586;
constexpr double kSqrt3 = 1.7320508075688772;
constexpr int kSubsteps = 4; // 12.5 µs: L/R is 525 µs, and ωe·Lq·h/L < 0.02 up to the base speed
// dead-time error: the sign of the current, ramped over this band so that a current near 0 does not chatter
constexpr double kDeadtimeBand = 0.05; // [A]
} // namespace

void MotorModel::reset(const MotorParams &p, uint64_t seed, MotorFault fault) {
  p_ = p;
  fault_ = fault;
  rng_.seed(seed ^ 0xD21E5EEDULL);
  id_ = iq_ = i_open_ = i_short_ = peak_phase_ = theta_m_ = 0.0;
  for (double &i : i_abc_) i = 0.0;
  vbus_ = p.supply_v;
  // each amplifier's bias within ±10 counts of nominal; a broken one sits at 400 counts off
  std::uniform_real_distribution<double> bias(-10.0, 10.0);
  for (double &o : offset_) o = p.adc_bias + bias(rng_);
  if (fault == MotorFault::AmplifierOffset) offset_[1] += 400.0;
}

void MotorModel::abc_from_dq() {
  const double th = p_.pole_pairs * theta_m_;
  const double ia = id_ * std::cos(th) - iq_ * std::sin(th);
  const double ib_beta = id_ * std::sin(th) + iq_ * std::cos(th);
  i_abc_[0] = ia;
  i_abc_[1] = -0.5 * ia + 0.5 * kSqrt3 * ib_beta;
  i_abc_[2] = -0.5 * ia - 0.5 * kSqrt3 * ib_beta;
}

MotorSample MotorModel::sample() {
  MotorSample s{};
  const double counts_per_amp = p_.shunt * p_.amp_gain * 4096.0 / p_.adc_vref;
  for (int k = 0; k < 3; ++k) {
    double i = i_abc_[k];
    if (fault_ == MotorFault::PhaseShort) i += (k == 0 ? i_short_ : (k == 1 ? -i_short_ : 0.0));
    const double c = std::round(offset_[k] + i * counts_per_amp + p_.adc_noise * noise_(rng_));
    s.adc_phase[k] = static_cast<uint16_t>(std::clamp(c, 0.0, 4095.0));
  }
  const double v = std::round(vbus_ / p_.vbus_divider * 4096.0 / p_.adc_vref + p_.adc_noise * noise_(rng_));
  s.adc_vbus = static_cast<uint16_t>(std::clamp(v, 0.0, 4095.0));
  const double turns = fault_ == MotorFault::EncoderMissing ? 0.0 : (theta_m_ - p_.encoder_zero) / kTwoPi;
  const int64_t count = static_cast<int64_t>(std::floor(turns * p_.encoder_cpr));
  const int sign = fault_ == MotorFault::EncoderReversed ? -p_.encoder_sign : p_.encoder_sign;
  const int64_t signed_count = sign * count;
  s.encoder = static_cast<uint16_t>(((signed_count % p_.encoder_cpr) + p_.encoder_cpr) % p_.encoder_cpr);
  return s;
}

double MotorModel::period(const double d_in[3], bool pwm_on, double omega_m) {
  const double ts = 1.0 / p_.pwm_hz, h = ts / kSubsteps;
  const double we = p_.pole_pairs * omega_m;
  // The rotor turns ωe·Ts ≈ 0.05 rad a period at the base speed: the transforms take the period's mid angle.
  const double th = p_.pole_pairs * (theta_m_ + 0.5 * omega_m * ts);
  const double co = std::cos(th), si = std::sin(th);
  // leg voltages over the negative rail: the duty's share of the bus, less the dead time's share with the
  // sign of the current leaving the leg; with the switches off, the diodes clamp a leg to the rail its
  // current flows toward (the windings then see at most the bus: regeneration through the diodes)
  double v[3];
  for (int k = 0; k < 3; ++k) {
    const double sgn = std::clamp(i_abc_[k] / kDeadtimeBand, -1.0, 1.0);
    if (pwm_on) {
      const double d = std::clamp(d_in[k], 0.0, 1.0) - sgn * p_.deadtime_s * p_.pwm_hz;
      v[k] = std::clamp(d, 0.0, 1.0) * vbus_;
    } else {
      v[k] = sgn > 0.0 ? 0.0 : (sgn < 0.0 ? vbus_ : 0.5 * vbus_);
    }
  }
  double iq_sum = 0.0, id_sum = 0.0;
  if (fault_ == MotorFault::PhaseOpen) {
    // phase c open: one current through a and b, i_a = −i_b = i; back-EMF e_x = −ωe·ψ·sin(θe − 2πx/3)
    const double ea = -we * p_.flux * si;
    const double eb = -we * p_.flux * std::sin(th - kTwoPi / 3.0);
    const double l = 0.5 * (p_.ld + p_.lq);
    for (int s = 0; s < kSubsteps; ++s) {
      i_open_ += h * ((v[0] - v[1]) - 2.0 * p_.r_phase * i_open_ - (ea - eb)) / (2.0 * l);
      const double ialpha = i_open_, ibeta = -i_open_ / kSqrt3; // (2a − b − c)/3 and (b − c)/√3
      id_ = ialpha * co + ibeta * si;
      iq_ = -ialpha * si + ibeta * co;
      iq_sum += iq_, id_sum += id_;
    }
    i_abc_[0] = i_open_;
    i_abc_[1] = -i_open_;
    i_abc_[2] = 0.0;
  } else {
    const double va = (2.0 * v[0] - v[1] - v[2]) / 3.0, vb = (v[1] - v[2]) / kSqrt3;
    const double vd = va * co + vb * si, vq = -va * si + vb * co;
    for (int s = 0; s < kSubsteps; ++s) {
      const double did = (vd - p_.r_phase * id_ + we * p_.lq * iq_) / p_.ld;
      const double diq = (vq - p_.r_phase * iq_ - we * (p_.ld * id_ + p_.flux)) / p_.lq;
      id_ += h * did;
      iq_ += h * diq;
      iq_sum += iq_, id_sum += id_;
    }
    theta_m_ += omega_m * ts;
    abc_from_dq();
    theta_m_ -= omega_m * ts;
  }
  // the bridge's draw on the bus capacitor, averaged over the period
  const double vb_safe = std::max(vbus_, 1e-3);
  double i_dc = p_.board_current;
  for (int k = 0; k < 3; ++k) i_dc += (v[k] / vb_safe) * i_abc_[k];
  if (fault_ == MotorFault::PhaseShort) {
    // terminals a and b shorted: the legs drive the short directly
    i_short_ = pwm_on ? (v[0] - v[1]) / p_.short_r : 0.0;
    i_dc += ((v[0] - v[1]) / vb_safe) * i_short_;
  }
  peak_phase_ = std::fabs(i_short_);
  for (int k = 0; k < 3; ++k) peak_phase_ = std::max(peak_phase_, std::fabs(i_abc_[k]));
  // The bus: with the supply conducting it relaxes toward V_s − R_s·i_dc with τ = R_s·C (10 µs, shorter than
  // the period: solved exactly); the supply cannot sink, so above V_s only the capacitor takes the current.
  const double decay = std::exp(-ts / (p_.supply_r * p_.bus_c));
  if (i_dc <= 0.0) {
    // regenerating: the capacitor takes the current; below V_s the supply also lifts it back toward V_s
    vbus_ -= ts * i_dc / p_.bus_c;
    if (vbus_ < p_.supply_v) vbus_ = p_.supply_v + (vbus_ - p_.supply_v) * decay;
  } else if (vbus_ > p_.supply_v) {
    vbus_ = std::max(vbus_ - ts * i_dc / p_.bus_c, p_.supply_v); // the capacitor alone, down to V_s
  } else {
    const double v_eq = p_.supply_v - p_.supply_r * i_dc;
    vbus_ = v_eq + (vbus_ - v_eq) * decay;
  }
  vbus_ = std::max(vbus_, 0.0);
  theta_m_ += omega_m * ts;
  const double iq_mean = iq_sum / kSubsteps, id_mean = id_sum / kSubsteps;
  return 1.5 * p_.pole_pairs * (p_.flux * iq_mean + (p_.ld - p_.lq) * id_mean * iq_mean);
}

} // namespace poursim
