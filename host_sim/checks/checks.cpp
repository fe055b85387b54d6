// SPDX-License-Identifier: MIT
// Retention and sloshing measurements, and the hydrostatic and linear-wave references they are judged by.
#include "poursim/checks.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "poursim_internal.hpp"
#include "world.hpp"

using poursim::set_error;

namespace {

constexpr double kG = 9.81;     // [m/s²]
constexpr double kDeg = M_PI / 180.0;

struct Pt {
  double x, y;
};

// Area of the part of a convex polygon where a·x + b·y <= c (Sutherland–Hodgman against one line).
double clipped_area(const std::vector<Pt> &poly, double a, double b, double c) {
  std::vector<Pt> out;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Pt &p = poly[i], &q = poly[(i + 1) % poly.size()];
    double fp = a * p.x + b * p.y - c, fq = a * q.x + b * q.y - c;
    if (fp <= 0) out.push_back(p);
    if ((fp < 0) != (fq < 0) && fp != fq) {
      double t = fp / (fp - fq);
      out.push_back({p.x + t * (q.x - p.x), p.y + t * (q.y - p.y)});
    }
  }
  double area = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    const Pt &p = out[i], &q = out[(i + 1) % out.size()];
    area += p.x * q.y - q.x * p.y;
  }
  return 0.5 * std::fabs(area);
}

// The liquid's centre of mass across the bucket, in the bucket's frame [m]; circles inside it only.
double com_across(poursim_world_t *w, const poursim_config_t &c, std::vector<float> &xy, std::vector<uint8_t> &reg) {
  poursim_obs_t o;
  poursim_observe(w, &o);
  int n = poursim_particles(w, xy.data(), nullptr, static_cast<int>(reg.size()));
  poursim_particle_regions(w, reg.data(), n);
  const double cs = std::cos(o.theta), sn = std::sin(o.theta);
  double sum = 0;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    if (reg[static_cast<size_t>(i)] != 0) continue;
    const double dx = static_cast<double>(xy[static_cast<size_t>(2 * i)]);
    const double dy = static_cast<double>(xy[static_cast<size_t>(2 * i + 1)]) - c.pivot_height;
    sum += dx * cs - dy * sn;
    ++k;
  }
  return k > 0 ? sum / k : 0.0;
}

// One servo tilt: V_rotating as the tilt passes each whole degree up to theta_end, added into kept.
int retention_run(const poursim_config_t &c, uint32_t seed, double rate, double theta_end, int samples,
                  double *kept, char *err, size_t err_len) {
  poursim_world_t *w = poursim_create(&c, err, err_len);
  if (w == nullptr) return POURSIM_EINVAL;
  int rc = poursim_reset(w, seed);
  poursim_obs_t o;
  poursim_observe(w, &o);
  for (int step = 0, k = 0; rc == POURSIM_OK && k < samples; ++step) {
    for (; k < samples && o.theta >= k * kDeg - 1e-9; ++k) kept[k] += o.v_rotating;
    if (k < samples) rc = poursim_step_servo(w, std::min(theta_end, rate * step * c.dt), &o);
  }
  if (rc != POURSIM_OK) set_error(err, err_len, rc, "seed %u: %s", seed, poursim_world_error(w));
  poursim_destroy(w);
  return rc;
}

} // namespace

extern "C" double poursim_ideal_retained(double width, double depth, double fill_depth, double theta) {
  // Bucket frame: x across (+ toward the lip that goes down), y up from the bottom. Tilted clockwise by
  // θ, a point's height is −x·sinθ + y·cosθ; the lower lip is (width/2, depth).
  const double hw = 0.5 * width, s = std::sin(theta), c = std::cos(theta);
  const double lip = -hw * s + depth * c;
  std::vector<Pt> box = {{-hw, 0}, {hw, 0}, {hw, depth}, {-hw, depth}};
  double below = clipped_area(box, -s, c, lip), fill = width * fill_depth;
  return std::min(fill, below) / fill;
}

extern "C" double poursim_slosh_theory_hz(double width, double fill_depth) {
  double k = M_PI / width;
  return std::sqrt(kG * k * std::tanh(k * fill_depth)) / (2.0 * M_PI);
}

extern "C" int poursim_measure_retention(const poursim_config_t *cfg, uint32_t seed, int n_seeds, double rate,
                                         double theta_end, poursim_retention_t *out, char *err, size_t err_len) {
  if (cfg == nullptr || out == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "retention: NULL argument");
  if (!(rate > 0.0 && rate <= 10.0) || !(theta_end > 0.0 && theta_end <= M_PI) || n_seeds < 1 || n_seeds > 100)
    return set_error(err, err_len, POURSIM_EINVAL, "retention: rate %g rad/s, end %g rad or %d seeds out of range",
                     rate, theta_end, n_seeds);
  poursim_config_t c = *cfg;
  c.episode_s = std::max(c.episode_s, theta_end / rate + 1.0);
  c.theta_max = std::max(c.theta_max, std::min(3.1, theta_end + 0.05));
  const double depth = c.bucket_height - c.bucket_wall;
  out->n = std::min(POURSIM_RETENTION_MAX, static_cast<int>(std::floor(theta_end / kDeg + 1e-9)) + 1);
  std::fill(out->kept, out->kept + POURSIM_RETENTION_MAX, 0.0);
  for (int k = 0; k < n_seeds; ++k) {
    int rc = retention_run(c, seed + static_cast<uint32_t>(k), rate, theta_end, out->n, out->kept, err, err_len);
    if (rc != POURSIM_OK) return rc;
  }
  out->onset = out->ideal_onset = -1.0;
  double sq = 0.0;
  for (int k = 0; k < out->n; ++k) {
    out->theta[k] = k * kDeg;
    out->kept[k] /= n_seeds;
    out->ideal[k] = poursim_ideal_retained(c.bucket_inner_width, depth, c.fill_depth, k * kDeg);
    if (out->onset < 0 && out->kept[k] <= 0.995) out->onset = out->theta[k];
    if (out->ideal_onset < 0 && out->ideal[k] <= 0.995) out->ideal_onset = out->theta[k];
    sq += (out->kept[k] - out->ideal[k]) * (out->kept[k] - out->ideal[k]);
  }
  out->rms_gap = std::sqrt(sq / out->n);
  return POURSIM_OK;
}

extern "C" int poursim_measure_slosh(const poursim_config_t *cfg, uint32_t seed, int n_seeds, double tilt,
                                     double ramp_s, double hold_s, double *trace, int trace_cap, poursim_slosh_t *out,
                                     char *err, size_t err_len) {
  if (cfg == nullptr || out == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "slosh: NULL argument");
  if (!(std::fabs(tilt) <= 0.5) || !(ramp_s > 0.0 && ramp_s <= 5.0) || !(hold_s >= 1.0 && hold_s <= 60.0) ||
      n_seeds < 1 || n_seeds > 100)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "slosh: tilt %g rad, ramp %g s, hold %g s or %d seeds out of range", tilt, ramp_s, hold_s, n_seeds);
  poursim_config_t c = *cfg;
  c.episode_s = std::max(c.episode_s, ramp_s + hold_s + 1.0);
  const int ramp = static_cast<int>(std::lround(ramp_s / c.dt)), hold = static_cast<int>(std::lround(hold_s / c.dt));
  std::vector<double> x(static_cast<size_t>(hold), 0.0);
  for (int k = 0; k < n_seeds; ++k) {
    poursim_world_t *w = poursim_create(&c, err, err_len);
    if (w == nullptr) return POURSIM_EINVAL;
    int rc = poursim_reset(w, seed + static_cast<uint32_t>(k));
    const int n = poursim_particle_count(w);
    std::vector<float> xy(static_cast<size_t>(2 * n));
    std::vector<uint8_t> reg(static_cast<size_t>(n));
    for (int step = 0; rc == POURSIM_OK && step < ramp + hold; ++step) {
      rc = poursim_step_servo(w, step < ramp ? tilt * step / ramp : tilt, nullptr);
      if (step >= ramp) x[static_cast<size_t>(step - ramp)] += com_across(w, c, xy, reg) / n_seeds;
    }
    if (rc != POURSIM_OK) set_error(err, err_len, rc, "slosh, seed %u: %s", seed + static_cast<uint32_t>(k), poursim_world_error(w));
    poursim_destroy(w);
    if (rc != POURSIM_OK) return rc;
  }
  // The oscillation about its equilibrium: remove the least-squares line through the hold.
  const size_t m = x.size();
  double st = 0, sx = 0, stt = 0, stx = 0;
  for (size_t i = 0; i < m; ++i) {
    const double t = static_cast<double>(i);
    st += t, sx += x[i], stt += t * t, stx += t * x[i];
  }
  const double md = static_cast<double>(m), slope = (md * stx - st * sx) / (md * stt - st * st);
  const double icpt = (sx - slope * st) / md;
  std::vector<double> osc(m);
  for (size_t i = 0; i < m; ++i) osc[i] = x[i] - icpt - slope * static_cast<double>(i);
  // The wave decays within a few periods; later the agitation's slow wander dominates. Analyse the first
  // 2.5 s; the last half of the hold gives the noise floor.
  const size_t win_n = std::min(m, static_cast<size_t>(std::lround(2.5 / c.dt)));
  double noise = 0;
  for (size_t i = m / 2; i < m; ++i) noise += osc[i] * osc[i];
  noise = std::sqrt(noise / static_cast<double>(m - m / 2));
  // Ring-down fit: x(t) = e^(−λt)·(a·cos ωt + b·sin ωt) + c + d·t by least squares over the first 2.5 s,
  // λ and ω on a grid (coarse, then fine around the best), the four linear terms solved at each point.
  auto residual = [&](double f, double lam, double *amp) {
    double M[4][5] = {};
    for (size_t i = 0; i < win_n; ++i) {
      const double t = static_cast<double>(i) * c.dt, e = std::exp(-lam * t);
      const double phi[4] = {e * std::cos(2.0 * M_PI * f * t), e * std::sin(2.0 * M_PI * f * t), 1.0, t};
      for (int r = 0; r < 4; ++r) {
        for (int q = 0; q < 4; ++q) M[r][q] += phi[r] * phi[q];
        M[r][4] += phi[r] * osc[i];
      }
    }
    for (int k = 0; k < 4; ++k) { // Gauss–Jordan; the basis is well conditioned on this window
      for (int r = 0; r < 4; ++r) {
        if (r == k) continue;
        const double g = M[r][k] / M[k][k];
        for (int q = k; q < 5; ++q) M[r][q] -= g * M[k][q];
      }
    }
    double sq = 0, coef[4];
    for (int k = 0; k < 4; ++k) coef[k] = M[k][4] / M[k][k];
    for (size_t i = 0; i < win_n; ++i) {
      const double t = static_cast<double>(i) * c.dt, e = std::exp(-lam * t);
      const double model = e * (coef[0] * std::cos(2.0 * M_PI * f * t) + coef[1] * std::sin(2.0 * M_PI * f * t)) +
                           coef[2] + coef[3] * t;
      sq += (osc[i] - model) * (osc[i] - model);
    }
    if (amp != nullptr) *amp = std::hypot(coef[0], coef[1]);
    return sq;
  };
  double best = -1, bf = 0, bl = 0;
  auto search = [&](double f0, double f1, double df, double l0, double l1, double dl) {
    for (double f = f0; f <= f1 + 1e-12; f += df)
      for (double lam = std::max(0.0, l0); lam <= l1 + 1e-12; lam += dl) {
        double r = residual(f, lam, nullptr);
        if (best < 0 || r < best) best = r, bf = f, bl = lam;
      }
  };
  search(0.5, 5.0, 0.05, 0.0, 8.0, 0.25);
  search(bf - 0.05, bf + 0.05, 0.005, bl - 0.25, bl + 0.25, 0.025);
  double amp = 0;
  residual(bf, bl, &amp);
  const double omega = 2.0 * M_PI * bf;
  out->freq_theory = poursim_slosh_theory_hz(c.bucket_inner_width, c.fill_depth);
  out->freq = std::sqrt(omega * omega + bl * bl) / (2.0 * M_PI); // undamped natural frequency
  out->damping = bl / std::sqrt(omega * omega + bl * bl);
  out->amplitude = amp;
  out->noise = noise;
  out->n = 0;
  for (size_t i = 0; trace != nullptr && i < m && static_cast<int>(i) < trace_cap; ++i) trace[out->n++] = osc[i];
  return POURSIM_OK;
}

// ---- The rig ----

namespace {

struct WorldGuard { // destroys a world on every path out
  poursim_world_t *w = nullptr;
  ~WorldGuard() { poursim_destroy(w); }
};

// The empty U about the pivot, by hand: its mass spread over the three boxes by area; each box's inertia
// about its own centre (w² + h²)/12 plus the parallel-axis term. com_y: its centre of mass below the pivot.
double u_inertia(const poursim_config_t &c, double *com_y) {
  const double wi = 0.5 * c.bucket_inner_width, t = c.bucket_wall, hh = 0.5 * c.bucket_height;
  struct Box {
    double w, h, x, y;
  } boxes[3] = {{2 * wi + 2 * t, t, 0.0, -hh + 0.5 * t}, {t, 2 * hh, -wi - 0.5 * t, 0.0}, {t, 2 * hh, wi + 0.5 * t, 0.0}};
  double area = 0, inertia = 0, my = 0;
  for (const Box &b : boxes) area += b.w * b.h;
  for (const Box &b : boxes) {
    const double m = c.bucket_mass * b.w * b.h / area;
    inertia += m * ((b.w * b.w + b.h * b.h) / 12.0 + b.x * b.x + b.y * b.y);
    my += m * b.y;
  }
  *com_y = my / c.bucket_mass;
  return inertia;
}

// A world of c with the liquid taken out (and the stops too with free_spin). The joint was holding the
// liquid's weight when it went: 0.2 s at rest lets that warm-started impulse die out.
poursim_world_t *empty_world(const poursim_config_t &c, bool free_spin, char *err, size_t err_len) {
  poursim_world_t *w = poursim_create(&c, err, err_len);
  if (w == nullptr) return nullptr;
  poursim::empty_bucket(w, free_spin);
  for (int k = 0; k < static_cast<int>(std::lround(0.2 / c.dt)); ++k) poursim_step_servo(w, 0.0, nullptr);
  return w;
}

} // namespace

extern "C" int poursim_measure_drive(const poursim_config_t *cfg, poursim_drive_check_t *out, char *err,
                                     size_t err_len) {
  if (cfg == nullptr || out == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "measure_drive: NULL argument");
  *out = poursim_drive_check_t{};
  const poursim_config_t &c = *cfg;
  poursim_obs_t o;
  double com_y;
  out->inertia_bucket = u_inertia(c, &com_y);
  out->inertia_expected = out->inertia_bucket + c.motor_rotor_inertia * c.gear_ratio * c.gear_ratio;
  // Latency: torque well above the friction is commanded at call 10; the bucket moves in the step that
  // the drive delivers it.
  {
    WorldGuard g{empty_world(c, false, err, err_len)};
    if (g.w == nullptr) return POURSIM_EINVAL;
    const double a = std::min(1.0, (c.friction_coulomb + 0.2 * c.motor_peak_torque) / c.tau_max);
    out->latency_ticks = -1;
    for (int k = 0; k < 10 + 200 && out->latency_ticks < 0; ++k) {
      poursim_step(g.w, k >= 10 ? a : 0.0, &o);
      if (k >= 10 && o.omega > 1e-5) out->latency_ticks = k - 10;
    }
  }
  // Reflected inertia: spin up from rest at upright with half the command for 20 steps; each step's
  // angular acceleration against its net torque (delivered − Coulomb − viscous − the U's gravity).
  {
    WorldGuard g{empty_world(c, false, err, err_len)};
    if (g.w == nullptr) return POURSIM_EINVAL;
    poursim_observe(g.w, &o);
    double sum_tau = 0, sum_alpha = 0, omega0 = o.omega, theta0 = o.theta;
    for (int k = 0; k < c.command_latency_ticks + 20; ++k) {
      poursim_step(g.w, 0.5, &o);
      if (o.motor_torque <= c.friction_coulomb) {
        omega0 = o.omega, theta0 = o.theta;
        continue;
      }
      const double gravity = c.bucket_mass * kG * com_y * std::sin(theta0); // com_y < 0: pulls back to upright
      sum_tau += o.motor_torque - c.friction_coulomb - c.friction_viscous * omega0 + gravity;
      sum_alpha += (o.omega - omega0) / c.dt;
      omega0 = o.omega, theta0 = o.theta;
    }
    out->inertia_measured = sum_alpha > 0 ? sum_tau / sum_alpha : -1.0;
  }
  // Coulomb breakaway: the command ramps at 1 N·m/s from 0; the bucket at upright (no gravity torque)
  // stays put until the delivered torque passes the friction.
  {
    WorldGuard g{empty_world(c, false, err, err_len)};
    if (g.w == nullptr) return POURSIM_EINVAL;
    out->breakaway_torque = -1.0;
    const int n = static_cast<int>(std::lround((c.friction_coulomb + 1.0) / c.dt));
    for (int k = 0; k < n && out->breakaway_torque < 0; ++k) {
      poursim_step(g.w, (k * c.dt) / c.tau_max, &o);
      if (std::fabs(o.omega) > 1e-5) out->breakaway_torque = o.motor_torque;
    }
  }
  // Terminal speed on the torque–speed line: full command, no stops, two Coulomb loads. Gravity on the
  // U's offset centre of mass averages out over the ~3 turns a second.
  for (int r = 0; r < 2; ++r) {
    poursim_config_t cr = c;
    if (r == 1) cr.friction_coulomb = 10.0;
    WorldGuard g{empty_world(cr, true, err, err_len)};
    if (g.w == nullptr) return POURSIM_EINVAL;
    const int n = static_cast<int>(std::lround(1.5 / c.dt)), tail = static_cast<int>(std::lround(1.0 / c.dt));
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      poursim_step(g.w, 1.0, &o);
      if (k >= n - tail) sum += o.omega;
    }
    const double P = cr.motor_peak_torque;
    out->terminal_load[r] = cr.friction_coulomb;
    out->terminal_speed[r] = sum / tail;
    // ω = ω₀(1 − (τ_c + bω)/P) → ω = ω₀(1 − τ_c/P)/(1 + ω₀b/P), where the line is below the command.
    out->terminal_expected[r] = cr.motor_no_load_speed * (1.0 - cr.friction_coulomb / P) /
                                (1.0 + cr.motor_no_load_speed * cr.friction_viscous / P);
  }
  // Friction at steady speeds: a speed loop (gravity fed forward) holds each speed from upright, no stops;
  // after 0.3 s of spin-up, each step's friction by Newton (delivered − gravity − J·α) is averaged over
  // one radian of travel.
  static const double kSpeeds[POURSIM_FRICTION_SPEEDS] = {0.2, 0.5, 1.0, 1.5, 2.0};
  const double gain = out->inertia_expected / 0.02; // [N·m per rad/s]: a 20 ms speed loop
  for (int r = 0; r < POURSIM_FRICTION_SPEEDS; ++r) {
    WorldGuard g{empty_world(c, true, err, err_len)};
    if (g.w == nullptr) return POURSIM_EINVAL;
    const double v = kSpeeds[r];
    const int spin = static_cast<int>(std::lround(0.3 / c.dt)), n = spin + static_cast<int>(std::lround(1.0 / v / c.dt));
    poursim_observe(g.w, &o);
    double omega0 = o.omega, theta0 = o.theta, sum_f = 0, sum_w = 0;
    for (int k = 0; k < n; ++k) {
      const double gravity = c.bucket_mass * kG * com_y * std::sin(theta0);
      const double tau = c.friction_coulomb + c.friction_viscous * v - gravity + gain * (v - omega0);
      poursim_step(g.w, tau / c.tau_max, &o);
      if (k >= spin) {
        sum_f += o.motor_torque + gravity - out->inertia_expected * (o.omega - omega0) / c.dt;
        sum_w += o.omega;
      }
      omega0 = o.omega, theta0 = o.theta;
    }
    out->friction_speed[r] = sum_w / (n - spin);
    out->friction_measured[r] = sum_f / (n - spin);
    out->friction_expected[r] = c.friction_coulomb + c.friction_viscous * out->friction_speed[r];
  }
  return POURSIM_OK;
}

namespace {

// E[(q(x + n) − q(x))²]^½ for n ~ N(0, σ²), q rounding to multiples of res, x spread evenly over a step.
double quantised_noise_rms(double sigma, double res) {
  if (sigma <= 0) return 0.0;
  const int kU = 400, kK = static_cast<int>(std::ceil(8.0 * sigma / res)) + 2;
  auto phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  double e = 0;
  for (int i = 0; i < kU; ++i) {
    const double u = -0.5 + (i + 0.5) / kU; // x's offset from its level [steps]
    for (int k = -kK; k <= kK; ++k) {
      const double p = phi((k + 0.5 - u) * res / sigma) - phi((k - 0.5 - u) * res / sigma);
      e += p * (k * res) * (k * res);
    }
  }
  return std::sqrt(e / kU);
}

} // namespace

extern "C" int poursim_measure_sensors(const poursim_config_t *cfg, uint32_t seed, poursim_sensor_check_t *out,
                                       char *err, size_t err_len) {
  if (cfg == nullptr || out == nullptr)
    return set_error(err, err_len, POURSIM_EINVAL, "measure_sensors: NULL argument");
  *out = poursim_sensor_check_t{};
  const poursim_config_t &c = *cfg;
  // 0: the config's sensors; 1: the same without noise; 2: every step, no lag, no noise (the reference).
  poursim_config_t cs[3] = {c, c, c};
  cs[1].scale_noise_g = 0.0;
  cs[2].scale_noise_g = 0.0;
  cs[2].scale_delay_s = 0.0;
  cs[2].scale_rate_hz = 1.0 / c.dt;
  WorldGuard g[3];
  for (int i = 0; i < 3; ++i) {
    g[i].w = poursim_create(&cs[i], err, err_len);
    if (g[i].w == nullptr) return POURSIM_EINVAL;
    if (poursim_reset(g[i].w, seed) != POURSIM_OK)
      return set_error(err, err_len, POURSIM_ENUMERIC, "measure_sensors: %s", poursim_world_error(g[i].w));
  }
  const poursim_config_t &ep = *poursim_episode_config(g[0].w);
  const int n = poursim_particle_count(g[2].w);
  const double particle_g = 1000.0 * poursim::liquid_mass(&ep) / n;
  out->liquid_g = particle_g * n;
  // Held upright 1 s, tilted at 0.5 rad/s to 125°, held 3 s for the target's liquid to settle.
  const double rate = 0.5, theta_end = 125 * kDeg;
  const int k_tilt = static_cast<int>(std::lround(1.0 / c.dt));
  const int k_tilted = k_tilt + static_cast<int>(std::lround(theta_end / rate / c.dt));
  const int n_steps = k_tilted + static_cast<int>(std::lround(3.0 / c.dt));
  const int k_last_s = n_steps - static_cast<int>(std::lround(1.0 / c.dt));
  const int k_rest = static_cast<int>(std::lround(0.2 / c.dt));
  const int avg = std::max(1, static_cast<int>(std::lround(0.05 / c.dt)));
  std::vector<int32_t> ref(static_cast<size_t>(n_steps)), quiet(static_cast<size_t>(n_steps));
  std::vector<uint8_t> before(static_cast<size_t>(n), 0), reg(static_cast<size_t>(n), 0);
  std::vector<double> impact(static_cast<size_t>(n_steps), 0.0), reading(static_cast<size_t>(n_steps), 0.0);
  std::vector<int> conv; // steps at which the noise-free reading changed (a conversion)
  const double counts = std::ldexp(1.0, ep.encoder_bits);
  double rest_rot = 0, rest_tgt = 0, inside_last = 0, momentum = 0, impulse = 0, noise_sq = 0, enc_err = 0;
  poursim_particle_regions(g[2].w, before.data(), n);
  poursim_obs_t o[3];
  for (int k = 0; k < n_steps; ++k) {
    const double theta_ref = k < k_tilt ? 0.0 : std::min(theta_end, rate * (k - k_tilt) * c.dt);
    for (int i = 0; i < 3; ++i)
      if (poursim_step_servo(g[i].w, theta_ref, &o[i]) != POURSIM_OK)
        return set_error(err, err_len, POURSIM_ENUMERIC, "measure_sensors: %s", poursim_world_error(g[i].w));
    const poursim_obs_t &r = o[2];
    const double e = std::fabs(o[0].encoder - r.theta * counts / (2.0 * M_PI));
    enc_err = std::max(enc_err, std::min(e, std::fabs(e - counts))); // wrapped below upright
    const size_t ks = static_cast<size_t>(k);
    ref[ks] = r.scale_rotating_g;
    quiet[ks] = o[1].scale_rotating_g;
    if (k >= k_rest && k < k_tilt) rest_rot += r.scale_rotating_g;
    // The noise-free reading changes at every conversion while the bucket tilts (the load moves each step).
    if (k >= k_tilt && k < k_tilted && quiet[ks] != quiet[ks - 1]) {
      conv.push_back(k);
      const double d = static_cast<double>(o[0].scale_rotating_g) - quiet[ks];
      noise_sq += d * d;
    }
    // Momentum carried into the target's interior (and out of it) by the particles crossing its bounds.
    poursim_particle_regions(g[2].w, reg.data(), n);
    int inside = 0;
    for (int i = 0; i < n; ++i) {
      const size_t is = static_cast<size_t>(i);
      inside += reg[is] == 1;
      if ((reg[is] == 1) != (before[is] == 1)) {
        const double v_down = -static_cast<double>(b2Body_GetLinearVelocity(g[2].w->circles[is]).y);
        momentum += (reg[is] == 1 ? 1.0 : -1.0) * particle_g * v_down;
      }
      before[is] = reg[is];
    }
    impact[ks] = r.scale_target_g - particle_g * inside;
    reading[ks] = r.scale_target_g;
    impulse += impact[ks] * c.dt;
    if (k >= k_last_s) {
      rest_tgt += r.scale_target_g;
      inside_last += particle_g * inside;
    }
  }
  out->hash_unchanged = poursim_trajectory_hash(g[0].w) == poursim_trajectory_hash(g[2].w) &&
                        poursim_trajectory_hash(g[1].w) == poursim_trajectory_hash(g[2].w);
  out->rest_rotating_g = rest_rot / (k_tilt - k_rest);
  out->rest_target_g = rest_tgt / (n_steps - k_last_s);
  out->target_liquid_g = inside_last / (n_steps - k_last_s);
  out->impact_impulse_gs = impulse;
  out->impact_expected_gs = momentum / kG;
  // The impact term's largest 50 ms mean while the liquid arrives.
  double window = 0;
  out->impact_peak_g = -1e300;
  for (int k = 0; k < k_last_s; ++k) {
    window += impact[static_cast<size_t>(k)];
    if (k >= avg) window -= impact[static_cast<size_t>(k - avg)];
    if (k >= avg && window / avg > out->impact_peak_g) {
      out->impact_peak_g = window / avg;
      out->impact_peak_reading_g = reading[static_cast<size_t>(k)];
    }
  }
  // Rate: a filtered reading may stay the same over a conversion, so the intervals between changes are
  // whole numbers of conversion periods; the median interval names the period, the total time refines it.
  std::vector<int> gaps;
  for (size_t i = 1; i < conv.size(); ++i) gaps.push_back(conv[i] - conv[i - 1]);
  if (!gaps.empty()) {
    std::vector<int> sorted = gaps;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double p0 = sorted[sorted.size() / 2];
    double periods = 0;
    for (int gap : gaps) periods += std::max(1.0, std::nearbyint(gap / p0));
    out->update_rate_hz = periods / ((conv.back() - conv.front()) * c.dt);
  }
  // Filter: the span over which the every-step reference, averaged, gives each conversion (within the
  // reference's own rounding: half a resolution each way).
  std::vector<double> prefix(static_cast<size_t>(n_steps) + 1, 0.0);
  for (size_t k = 0; k < static_cast<size_t>(n_steps); ++k) prefix[k + 1] = prefix[k] + ref[k];
  const int max_span = static_cast<int>(std::lround(std::min(1.0, 2.0 * c.scale_delay_s + 0.05) / c.dt));
  int best = 0, best_span = 1;
  for (int span = 1; span <= max_span; ++span) {
    int hits = 0;
    for (int k : conv) {
      if (k + 1 < span) continue;
      const double mean = (prefix[static_cast<size_t>(k) + 1] - prefix[static_cast<size_t>(k + 1 - span)]) / span;
      hits += std::fabs(quiet[static_cast<size_t>(k)] - mean) <= ep.scale_resolution_g;
    }
    if (hits > best) best = hits, best_span = span;
  }
  out->delay_s = best_span * c.dt;
  out->delay_match = conv.empty() ? 0.0 : static_cast<double>(best) / static_cast<double>(conv.size());
  out->noise_rms_g = conv.empty() ? 0.0 : std::sqrt(noise_sq / static_cast<double>(conv.size()));
  out->noise_expected_g = quantised_noise_rms(ep.scale_noise_g, ep.scale_resolution_g);
  // Below upright: to the lower stop and held there.
  poursim_reset(g[0].w, seed);
  for (int k = 0; k < 300; ++k) {
    poursim_step_servo(g[0].w, c.theta_min, &o[0]);
    const double e = std::fabs(o[0].encoder - o[0].theta * counts / (2.0 * M_PI));
    enc_err = std::max(enc_err, std::min(e, std::fabs(e - counts)));
  }
  out->encoder_at_stop = o[0].encoder;
  out->encoder_max_error = enc_err;
  return POURSIM_OK;
}
