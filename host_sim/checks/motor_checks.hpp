// SPDX-License-Identifier: MIT
// The full drive's measurements (docs/motor.md, "Figures"): the current step, the torque at the shaft
// against speed, the bus through the shipped policy's pour and the return to upright. bench_motor prints
// them; tests/sim/test_motor_checks.cpp holds them to the bars.
#ifndef POURSIM_MOTOR_CHECKS_HPP
#define POURSIM_MOTOR_CHECKS_HPP

#include <cstdint>
#include <string>
#include <vector>

#include "poursim/poursim.h"

namespace poursim {

struct CurrentStep {
  double ref = 0;            // the q-current step [A]
  double rise_s = 0;         // 10 → 90 % of ref [s]
  double first_order_rise_s = 0; // ln 9/ωc: a delay-free first-order loop of the design bandwidth [s]
  double predicted_rise_s = 0;   // the designed loop (bandwidth ωc) with its 1.5-period delay [s]
  double overshoot = 0;      // (max − ref)/ref [-]
  double ss_error = 0;       // |mean of the last 2 ms − ref|/ref [-]
  std::vector<double> t, iq; // the trace, one sample a PWM period [s], [A]
};

// A q-current step of amps [A] on the locked rotor (ω = 0), 1 ms at zero then 9 ms at the step; the loop
// tuned for bandwidth_rad_s (0: the firmware's default).
CurrentStep measure_current_step(const poursim_config_t &c, double amps, uint32_t bandwidth_rad_s = 0);

struct TorquePoint {
  double omega = 0;    // output speed [rad/s]
  double command = 0;  // [N·m at the output]
  double delivered = 0; // mean shaft torque at the output over 10 ms after 30 ms [N·m]
};

// The base speed for a torque [N·m at the output]: the output speed at which the current loop's voltage
// limit is just enough for it [rad/s] (from the motor's R, L, ψ and the bus).
double base_speed(const poursim_config_t &c, double torque);

// The mean shaft torque over 10 ms after 30 ms of commanding torque at output speed omega [N·m].
double measure_shaft_torque(const poursim_config_t &c, double torque, double omega);

// The torque at the shaft at n_speeds speeds from 0 to the base speed of torque.
std::vector<TorquePoint> measure_torque_speed(const poursim_config_t &c, double torque, int n_speeds);

struct BusTrace {
  double peak_vbus = 0, min_vbus = 0, peak_current = 0; // [V], [V], [A]
  unsigned faults = 0;                                  // POUR_DRIVE_FAULT_*
  double poured = 0, spilled = 0;                       // of the pour [fraction]
  std::vector<double> t, vbus;                          // one sample a step [s], [V]
};

// The shipped policy's pour (weights at weights_path, the float policy through the safety envelope,
// poursim_rollout) with the drive of c (telemetry and trace only with drive = 1), then return_s of a PD return to upright: the bus and the faults.
// On error returns false with why.
bool measure_pour_bus(const poursim_config_t &c, const std::string &weights_path, uint32_t seed, double return_s,
                      BusTrace *out, std::string *why);

} // namespace poursim

#endif // POURSIM_MOTOR_CHECKS_HPP
