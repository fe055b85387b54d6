// SPDX-License-Identifier: MIT
// Retention and sloshing measurements, and the hydrostatic and linear-wave references they are judged by.
#include "poursim/checks.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "poursim_internal.hpp"

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
    double dx = xy[static_cast<size_t>(2 * i)], dy = static_cast<double>(xy[static_cast<size_t>(2 * i + 1)]) - c.pivot_height;
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
