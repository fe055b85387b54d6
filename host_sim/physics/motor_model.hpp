// SPDX-License-Identifier: MIT
// The bucket's motor, inverter and DC bus as the drive's current loop sees them (docs/motor.md): a PMSM in
// the dq frame (R, Ld, Lq, flux linkage, pole pairs), the inverter's phase voltages averaged over a PWM
// period from the duties and the bus (with the dead time's error), three low-side shunts through their
// amplifiers into 12-bit converters (gain, offset, quantisation, seeded noise), the bus capacitor fed by a
// supply with a source resistance that cannot sink current, and the motor encoder as TIM4 counts it.
// Injected faults: a phase open, two phases shorted, an encoder wired backwards, a broken amplifier, an
// encoder unplugged (its count stays where it was).
#ifndef POURSIM_MOTOR_MODEL_HPP
#define POURSIM_MOTOR_MODEL_HPP

#include <cstdint>
#include <random>

namespace poursim {

enum class MotorFault { None = 0, PhaseOpen = 1, PhaseShort = 2, EncoderReversed = 3, AmplifierOffset = 4, EncoderMissing = 5 };

struct MotorParams {
  // defaults: a placeholder; motor_params() fills every field from the firmware's configuration
  double r_phase = 0.2865;        // [Ω]
  double ld = 150.5e-6, lq = 150.5e-6; // [H]
  double flux = 0.0404 / 12.0;    // permanent-magnet flux linkage ψ = Kt/(1.5·pp) [Wb]
  int pole_pairs = 8;
  double pwm_hz = 20000.0;
  double deadtime_s = 800e-9;
  double supply_v = 24.0, supply_r = 0.05; // bench supply and its leads [V], [Ω]
  double bus_c = 200e-6;          // bus capacitance [F]
  double shunt = 0.003, amp_gain = 9.14, adc_vref = 3.3, adc_bias = 2048.0; // [Ω], [-], [V], [counts]
  double adc_noise = 1.0;         // RMS noise of a conversion [counts]
  double vbus_divider = 19.17;    // bus / ADC pin [-]
  int encoder_cpr = 4096;
  double encoder_zero = 0.0;      // rotor angle at which the encoder reads 0 [rad]: electrical offset pp·zero
  int encoder_sign = 1;           // +1: counts up as the rotor turns forward; -1: mounted the other way
  double short_r = 0.02;          // resistance of a phase-to-phase short, with the legs' on-resistance [Ω]
  double board_current = 0.05;    // the board's own draw on the bus (gate drivers, MCU, LDO) [A], assumed
};

// ADC readings at the PWM centre.
struct MotorSample {
  uint16_t adc_phase[3];
  uint16_t adc_vbus;
  uint16_t encoder;
};

class MotorModel {
 public:
  void reset(const MotorParams &p, uint64_t seed, MotorFault fault);
  // What the converters and the encoder read now.
  MotorSample sample();
  // One PWM period with duties d[3] in [0, 1] (pwm_on 0: all switches off, the diodes only) at motor speed
  // omega_m [rad/s]; advances the rotor angle by omega_m·Ts. Returns the mean electromagnetic torque over
  // the period [N·m at the motor].
  double period(const double d[3], bool pwm_on, double omega_m);
  double id() const { return id_; }
  double iq() const { return iq_; }
  double vbus() const { return vbus_; }
  // largest |phase current| in the last period [A] (the short's current included)
  double peak_phase() const { return peak_phase_; }
  double phase_current(int k) const { return i_abc_[k]; }

 private:
  void abc_from_dq();
  MotorParams p_;
  MotorFault fault_ = MotorFault::None;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
  double id_ = 0, iq_ = 0, i_open_ = 0, vbus_ = 0, theta_m_ = 0;
  double i_abc_[3] = {0, 0, 0}, i_short_ = 0, peak_phase_ = 0;
  double offset_[3] = {0, 0, 0};
};

} // namespace poursim

#endif // POURSIM_MOTOR_MODEL_HPP
