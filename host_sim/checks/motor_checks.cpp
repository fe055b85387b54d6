// SPDX-License-Identifier: MIT
// The full drive's measurements (motor_checks.hpp).
#include "motor_checks.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "foc_drive.hpp"
#include "poursim/weights_file.h"
#include "world.hpp"

namespace poursim {

namespace {
// the motor torque constant, gear and efficiency the firmware uses: torque at the output per q ampere
double output_torque_per_amp(const FocDrive &f) {
  return f.firmware_config().kt_unm_per_a * 1e-6 * f.gear() * f.efficiency();
}
// 10 → 90 % rise of the designed loop with its delay: the PI's zero cancels the winding's pole, leaving
// dx/dt = ωc·(1 − x(t − Td)); Td = 1.5 periods (the sample is a period old when its duties start, and the
// PWM holds them a period: half of it on average). Integrated at 0.1 µs.
double delayed_loop_rise(double wc, double td) {
  const double h = 1e-7;
  const size_t lag = static_cast<size_t>(std::lround(td / h));
  std::vector<double> x(lag + 1, 0.0);
  double t10 = -1, t90 = -1;
  for (size_t k = 0; t90 < 0 && k < 100000000u; ++k) {
    const double now = x.back(), delayed = x[x.size() - 1 - lag];
    x.push_back(now + h * wc * (1.0 - delayed));
    const double t = static_cast<double>(k + 1) * h;
    if (t10 < 0 && x.back() >= 0.1) t10 = t;
    if (t90 < 0 && x.back() >= 0.9) t90 = t;
  }
  return t90 - t10;
}

} // namespace

CurrentStep measure_current_step(const poursim_config_t &c, double amps, uint32_t bandwidth_rad_s) {
  FocDrive f;
  f.reset(c, c.seed, bandwidth_rad_s);
  CurrentStep r;
  r.ref = amps;
  r.first_order_rise_s = std::log(9.0) / f.firmware_config().bandwidth_rad_s;
  r.predicted_rise_s = delayed_loop_rise(f.firmware_config().bandwidth_rad_s, 1.5 / f.firmware_config().pwm_hz);
  const int per_ms = static_cast<int>(f.firmware_config().pwm_hz / 1000u);
  const double ts = 1.0 / f.firmware_config().pwm_hz;
  for (int ms = 0; ms < 10; ++ms) {
    f.command(ms == 0 ? 0.0 : amps * output_torque_per_amp(f), 0.0, 0.001);
    for (int k = 0; k < per_ms; ++k) {
      f.period(0.0);
      r.t.push_back((ms * per_ms + k + 1) * ts - 0.001);
      r.iq.push_back(f.model().iq());
    }
  }
  double t10 = -1, t90 = -1, peak = 0, tail = 0;
  int n_tail = 0;
  for (size_t k = 0; k < r.t.size(); ++k) {
    if (r.t[k] < 0) continue;
    if (t10 < 0 && r.iq[k] >= 0.1 * amps) t10 = r.t[k];
    if (t90 < 0 && r.iq[k] >= 0.9 * amps) t90 = r.t[k];
    peak = std::max(peak, r.iq[k]);
    if (r.t[k] >= 0.007) tail += r.iq[k], ++n_tail;
  }
  r.rise_s = t10 >= 0 && t90 >= 0 ? t90 - t10 : -1.0;
  r.overshoot = (peak - amps) / amps;
  r.ss_error = std::fabs(tail / std::max(1, n_tail) - amps) / amps;
  return r;
}

double base_speed(const poursim_config_t &c, double torque) {
  FocDrive f;
  f.reset(c, c.seed);
  const MotorParams p = motor_params(f.firmware_config(), c);
  const double iq = torque / output_torque_per_amp(f);
  // (R·iq + ωe·ψ)² + (ωe·L·iq)² = vmax², for ωe > 0, with the bus sagging under the load through the
  // supply's resistance: vbus = V_s − R_s·P/vbus, P = 1.5·(R·iq + ωe·ψ)·iq (a few fixed-point passes)
  double vbus = c.supply_voltage, we = 0.0;
  for (int pass = 0; pass < 8; ++pass) {
    const double vmax = 0.94 / std::sqrt(3.0) * vbus;
    const double a = p.flux * p.flux + std::pow(p.lq * iq, 2), b = 2.0 * p.r_phase * iq * p.flux;
    const double cc = std::pow(p.r_phase * iq, 2) - vmax * vmax;
    we = (-b + std::sqrt(b * b - 4.0 * a * cc)) / (2.0 * a);
    const double power = 1.5 * (p.r_phase * iq + we * p.flux) * iq;
    vbus = 0.5 * (c.supply_voltage + std::sqrt(c.supply_voltage * c.supply_voltage - 4.0 * p.supply_r * power));
  }
  return we / p.pole_pairs / f.gear();
}

double measure_shaft_torque(const poursim_config_t &c, double torque, double omega) {
  FocDrive f;
  f.reset(c, c.seed);
  double sum = 0;
  for (int ms = 0; ms < 40; ++ms) {
    const double t = f.step(torque, omega, 0.001);
    if (ms >= 30) sum += t;
  }
  return sum / 10.0;
}

std::vector<TorquePoint> measure_torque_speed(const poursim_config_t &c, double torque, int n_speeds) {
  std::vector<TorquePoint> pts;
  const double w_base = base_speed(c, torque);
  for (int k = 0; k < n_speeds; ++k) {
    TorquePoint p;
    p.omega = n_speeds > 1 ? w_base * k / (n_speeds - 1) : 0.0;
    p.command = torque;
    p.delivered = measure_shaft_torque(c, torque, p.omega);
    pts.push_back(p);
  }
  return pts;
}

bool measure_pour_bus(const poursim_config_t &cfg, const std::string &weights_path, uint32_t seed, double return_s,
                      BusTrace *out, std::string *why) {
  char err[POURSIM_ERR_LEN];
  auto file = std::make_unique<poursim_weights_file_t>();
  if (poursim_weights_load(weights_path.c_str(), file.get(), err, sizeof err) != POURSIM_OK) {
    *why = err;
    return false;
  }
  std::vector<double> w(static_cast<size_t>(POURSIM_N_FEATURES * file->n_actions)), levels(static_cast<size_t>(file->n_actions));
  poursim_policy_t pol;
  poursim_weights_float_policy(file.get(), w.data(), levels.data(), &pol);
  pol.greedy = 1;
  poursim_config_t c = cfg;
  c.tau_max = file->tau_max_mnm / 1000.0;
  poursim_world_t *world = poursim_create(&c, err, sizeof err);
  if (world == nullptr) {
    *why = err;
    return false;
  }
  const int steps = static_cast<int>(std::lround(c.episode_s / c.dt));
  std::vector<double> theta(static_cast<size_t>(steps));
  poursim_rollout_buffers_t bufs{};
  bufs.step_capacity = steps;
  bufs.step_theta = theta.data();
  poursim_episode_t ep{};
  int rc = poursim_rollout(world, &pol, seed, &bufs, &ep);
  poursim_drive_telemetry_t tel{};
  if (rc == POURSIM_OK) {
    // the return: a PD servo to upright within the policy's torque
    const int n = static_cast<int>(std::lround(return_s / c.dt));
    poursim_obs_t o;
    poursim_observe(world, &o);
    for (int k = 0; k < n && rc == POURSIM_OK; ++k) {
      const double tau = std::clamp(-(40.0 * o.theta + 12.0 * o.omega), -c.tau_max, c.tau_max);
      rc = poursim_step(world, tau / c.tau_max, &o);
    }
  }
  poursim_drive_telemetry(world, &tel);
  if (const FocDrive *f = world->drive.foc()) {
    const std::vector<float> &v = f->vbus_trace();
    for (size_t k = 0; k < v.size(); ++k) {
      out->t.push_back(static_cast<double>(k) * c.dt);
      out->vbus.push_back(v[k]);
    }
  }
  if (rc != POURSIM_OK) {
    *why = std::string("the pour failed: ") + poursim_world_error(world);
    poursim_destroy(world);
    return false;
  }
  poursim_destroy(world);
  out->peak_vbus = tel.peak_vbus;
  out->min_vbus = tel.min_vbus;
  out->peak_current = tel.peak_current;
  out->faults = tel.faults;
  out->poured = ep.poured;
  out->spilled = ep.spilled;
  return true;
}

} // namespace poursim
