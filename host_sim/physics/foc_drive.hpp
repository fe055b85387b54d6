// SPDX-License-Identifier: MIT
// The full drive (config drive = 1): the firmware's field-oriented current loop (pour::motor, the fixed-point
// code the board runs) closed around the motor, inverter and bus model at the PWM rate, 20 periods per 1 ms
// step, the gearbox between the motor and the bucket.
#ifndef POURSIM_FOC_DRIVE_HPP
#define POURSIM_FOC_DRIVE_HPP

#include <cstdint>
#include <vector>

#include "motor_model.hpp"
#include "poursim/poursim.h"

extern "C" {
#include "pour/drive.h"
}

namespace poursim {

// What a bench reads off the drive, over the episode so far.
struct FocTelemetry {
  double peak_current = 0; // largest |phase current| [A]
  double peak_vbus = 0;    // [V]
  double min_vbus = 0;     // [V]
  uint16_t faults = 0;     // POUR_DRIVE_FAULT_*
  uint16_t limits = 0;     // POUR_DRIVE_LIMIT_* seen (OR)
};

class FocDrive {
 public:
  // The firmware's default drive (its current loop tuned for bandwidth_rad_s if not 0), flux braking per
  // drive_regen, the model's fault; the start-up offset calibration runs here (the PWM off, 12.8 ms).
  void reset(const poursim_config_t &c, uint32_t seed, uint32_t bandwidth_rad_s = 0);
  // A motor unlike the firmware's configuration (what calibration is for): the model restarts with p, the
  // rig's fault kept, and the drive with its own configuration runs its start-up offsets again.
  void set_motor(const MotorParams &p, uint32_t seed);
  // Starts the drive's self-calibration (pour_drive_calibrate): POUR_OK, or POUR_EINVAL unless it runs.
  pour_status_t calibrate() { return pour_drive_calibrate(&drv_); }
  // Ends a running self-calibration as a stop or the e-stop does (pour_drive_calibrate_abort).
  void abort_calibration() { pour_drive_calibrate_abort(&drv_); }
  const pour_drive_t &drive() const { return drv_; }
  pour_drive_t &drive() { return drv_; } // for a port's code around the drive (the calibration's flow)
  // One step of dt: the command [N·m at the output] to the 1 kHz tick, then the periods of the current
  // loop at output speed omega [rad/s]. Returns the mean torque at the output [N·m].
  double step(double tau_cmd, double omega, double dt);
  // The 1 kHz tick alone (step's first half): the command and the output's motion over dt.
  void command(double tau_cmd, double omega, double dt);
  // One PWM period at output speed omega (the step above is made of these); the torque at the output.
  double period(double omega);
  bool brake_requested() const { return out_.brake != 0 && drv_.state != POUR_DRIVE_CALIBRATING; }
  // The current loop runs (it follows the torque command): not calibrating, not faulted.
  bool running() const { return drv_.state == POUR_DRIVE_RUN; }
  const FocTelemetry &telemetry() const { return tel_; }
  // The highest bus voltage of each step since the reset [V] (for plots).
  const std::vector<float> &vbus_trace() const { return vbus_trace_; }
  const pour_drive_output_t &output() const { return out_; }
  const MotorModel &model() const { return model_; }
  const pour_drive_config_t &firmware_config() const { return drv_.config; }
  double gear() const { return gear_; }
  double efficiency() const { return eff_; }

 private:
  pour_drive_t drv_{};
  pour_drive_output_t out_{};
  MotorModel model_;
  MotorParams params_;
  FocTelemetry tel_;
  double gear_ = 20.0, eff_ = 0.9;
  double duty_[3] = {0.5, 0.5, 0.5}; // the compares loaded at the next period's start
  bool pwm_on_ = false;
  MotorFault fault_ = MotorFault::None;
  std::vector<float> vbus_trace_;
  void start_offsets();
};

// The model's parameters from the firmware's configuration (one source for the motor's numbers) and the
// rig's bus keys.
MotorParams motor_params(const pour_drive_config_t &fw, const poursim_config_t &c);

} // namespace poursim

#endif // POURSIM_FOC_DRIVE_HPP
