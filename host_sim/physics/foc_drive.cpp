// SPDX-License-Identifier: MIT
// The firmware's current loop around the motor model (foc_drive.hpp).
#include "foc_drive.hpp"

#include <algorithm>
#include <cmath>

extern "C" {
#include "pour/board_facts.h"
}

namespace poursim {

MotorParams motor_params(const pour_drive_config_t &fw, const poursim_config_t &c) {
  MotorParams p;
  p.r_phase = fw.r_phase_uohm * 1e-6;
  p.ld = fw.ld_nh * 1e-9;
  p.lq = fw.lq_nh * 1e-9;
  p.pole_pairs = static_cast<int>(fw.pole_pairs);
  p.flux = fw.kt_unm_per_a * 1e-6 / (1.5 * fw.pole_pairs);
  p.pwm_hz = fw.pwm_hz;
  p.deadtime_s = fw.deadtime_ns * 1e-9;
  p.supply_v = c.supply_voltage;
  p.bus_c = c.bus_capacitance;
  // The board's analog chain as ST built it (pour/board_facts.h), not as the firmware believes it: a firmware
  // whose offset, sign or divider disagrees with the board sees it here as it would on the bench. The sign
  // rides on the gain: the amplifier's output falls as current flows into the motor.
  p.shunt = POUR_BOARD_SHUNT_UOHM * 1e-6;
  p.amp_gain = POUR_BOARD_CURRENT_SIGN * POUR_BOARD_INPUT_NETWORK_MILLI * 1e-3 * POUR_BOARD_PGA_GAIN;
  p.adc_vref = POUR_BOARD_ADC_VREF_MV * 1e-3;
  p.adc_bias = POUR_BOARD_BIAS_MV * 4096.0 / POUR_BOARD_ADC_VREF_MV;
  p.vbus_divider = static_cast<double>(POUR_BOARD_VBUS_R_TOP_OHM + POUR_BOARD_VBUS_R_BOTTOM_OHM) / POUR_BOARD_VBUS_R_BOTTOM_OHM;
  p.encoder_cpr = static_cast<int>(fw.encoder_cpr);
  return p;
}

void FocDrive::reset(const poursim_config_t &c, uint32_t seed, uint32_t bandwidth_rad_s) {
  pour_drive_config_t fw = pour_drive_default_config();
  if (bandwidth_rad_s != 0u) fw.bandwidth_rad_s = bandwidth_rad_s;
  fw.regen_enabled = static_cast<uint32_t>(c.drive_regen);
  fw.gear_ratio = static_cast<uint32_t>(std::lround(c.gear_ratio));
  (void)pour_drive_init(&drv_, &fw); // the defaults with a rig's gear ratio: validated by the config's range
  params_ = motor_params(fw, c);
  gear_ = c.gear_ratio;
  eff_ = fw.gear_efficiency_q15 / 32768.0;
  fault_ = static_cast<MotorFault>(c.drive_fault);
  model_.reset(params_, seed, fault_);
  start_offsets();
}

void FocDrive::set_motor(const MotorParams &p, uint32_t seed) {
  params_ = p;
  model_.reset(params_, seed, fault_);
  const pour_drive_config_t fw = drv_.config;
  (void)pour_drive_init(&drv_, &fw); // the configuration in force: valid
  start_offsets();
}

void FocDrive::start_offsets() {
  tel_ = FocTelemetry{};
  tel_.min_vbus = tel_.peak_vbus = model_.vbus();
  out_ = pour_drive_output_t{};
  pwm_on_ = false;
  for (double &d : duty_) d = 0.5;
  for (int k = 0; k < POUR_CURRENT_SENSE_CAL_SAMPLES + 1 && drv_.state == POUR_DRIVE_CALIBRATING; ++k) period(0.0);
  tel_.peak_current = 0.0;
  vbus_trace_.clear();
}

double FocDrive::period(double omega) {
  const MotorSample s = model_.sample();
  const pour_drive_sample_t in = {{s.adc_phase[0], s.adc_phase[1], s.adc_phase[2]}, s.adc_vbus, s.encoder};
  const double tau_m = model_.period(duty_, pwm_on_, omega * gear_);
  // the interrupt runs on this period's sample; its compares take effect at the next period
  pour_drive_isr(&drv_, &in, &out_);
  pwm_on_ = out_.pwm_enable != 0;
  for (int k = 0; k < 3; ++k) duty_[k] = static_cast<double>(out_.compare[k]) / drv_.period;
  tel_.peak_current = std::max(tel_.peak_current, model_.peak_phase());
  tel_.peak_vbus = std::max(tel_.peak_vbus, model_.vbus());
  tel_.min_vbus = std::min(tel_.min_vbus, model_.vbus());
  tel_.faults = static_cast<uint16_t>(tel_.faults | out_.faults);
  tel_.limits = static_cast<uint16_t>(tel_.limits | out_.limits);
  // the gearbox loses (1 − η) of the power that crosses it, whichever way it flows
  return tau_m * omega >= 0.0 ? tau_m * gear_ * eff_ : tau_m * gear_ / eff_;
}

void FocDrive::command(double tau_cmd, double omega, double dt) {
  const double mnm = std::clamp(tau_cmd * 1000.0, -2.0e9, 2.0e9);
  pour_drive_tick(&drv_, static_cast<int32_t>(std::lround(mnm)), static_cast<int32_t>(std::lround(omega * dt * 1e6)));
}

double FocDrive::step(double tau_cmd, double omega, double dt) {
  command(tau_cmd, omega, dt);
  const int n = std::max(1, static_cast<int>(std::lround(dt * drv_.config.pwm_hz)));
  double sum = 0.0, vmax = 0.0;
  for (int k = 0; k < n; ++k) {
    sum += period(omega);
    vmax = std::max(vmax, model_.vbus());
  }
  vbus_trace_.push_back(static_cast<float>(vmax));
  return sum / n;
}

} // namespace poursim
