// SPDX-License-Identifier: MIT
// Per step, in velocity form so that Box2D integrates the result and resolves the walls: a prediction
// of the positions under gravity, viscosity and agitation on each pair's relative normal velocity, the
// density measured on the prediction, and a push of each compressed pair apart as a velocity change.
// Loops run in a fixed order and the agitation draws from a seeded stream: a step is deterministic.
#include "fluid.hpp"

#include <algorithm>
#include <cmath>

namespace poursim {

namespace {

// xorshift64*, uniform in [-√3, √3): unit variance, bounded (a kick can never be huge).
double unit_noise(uint64_t &s) {
  s ^= s >> 12, s ^= s << 25, s ^= s >> 27;
  uint64_t r = s * 2685821657736338717ULL;
  return (static_cast<double>(r >> 11) * (1.0 / 9007199254740992.0) - 0.5) * 3.4641016151377544;
}

} // namespace

double fluid_rest_density(double spacing, double h) {
  // A liquid at rest packs like a triangular lattice: nearest distance a with a²·√3/2 = spacing².
  const double a = spacing * std::sqrt(2.0 / std::sqrt(3.0));
  double rho = 0.0;
  const int reach = static_cast<int>(std::ceil(h / a)) + 1;
  for (int i = -reach; i <= reach; ++i) {
    for (int j = -reach; j <= reach; ++j) {
      if (i == 0 && j == 0) continue;
      const double x = a * (i + 0.5 * j), y = a * (std::sqrt(3.0) / 2.0) * j;
      const double w = 1.0 - std::sqrt(x * x + y * y) / h;
      if (w > 0.0) rho += w * w;
    }
  }
  return rho;
}

void Fluid::configure(const FluidParams &p, int n, uint64_t seed) {
  p_ = p;
  n_ = n;
  rng_ = seed | 1u; // xorshift must not start at 0
  const size_t un = static_cast<size_t>(n);
  for (std::vector<double> *v : {&px_, &py_, &sx_, &sy_, &rho_}) v->assign(un, 0.0);
  cell_of_.assign(un, 0);
  sorted_.assign(un, 0);
  first_.assign(un + 1, 0);
  pairs_.assign(un * 8, Pair{});
  max_ratio_ = 0.0;
}

void Fluid::predict(double dt, double gy, const double *x, const double *y, const double *vx, const double *vy) {
  for (size_t i = 0; i < static_cast<size_t>(n_); ++i) {
    px_[i] = x[i] + dt * vx[i];
    py_[i] = y[i] + dt * (vy[i] + gy * dt);
  }
}

// Counting sort of the particles into cells of size h over their bounding box, then each particle
// against its own cell and four forward neighbours: every pair closer than h exactly once, in a fixed
// order.
void Fluid::find_pairs() {
  if (n_ < 2) return;
  double ox = px_[0], x1 = ox, oy = py_[0], y1 = oy; // the bounding box (min and max: no branches)
  for (size_t i = 1; i < static_cast<size_t>(n_); ++i) {
    ox = std::min(ox, px_[i]), x1 = std::max(x1, px_[i]);
    oy = std::min(oy, py_[i]), y1 = std::max(y1, py_[i]);
  }
  const double inv = 1.0 / p_.h;
  // The world keeps every position finite and inside it, so the grid stays small (< 10^4 cells).
  const int nx = static_cast<int>((x1 - ox) * inv) + 1, ny = static_cast<int>((y1 - oy) * inv) + 1;
  cell_start_.assign(static_cast<size_t>(nx) * static_cast<size_t>(ny) + 1, 0);
  for (size_t i = 0; i < static_cast<size_t>(n_); ++i) {
    int cx = std::min(nx - 1, static_cast<int>((px_[i] - ox) * inv));
    int cy = std::min(ny - 1, static_cast<int>((py_[i] - oy) * inv));
    cell_of_[i] = cy * nx + cx;
    cell_start_[static_cast<size_t>(cell_of_[i]) + 1]++;
  }
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = 0; i < n_; ++i) {
    const size_t slot = static_cast<size_t>(fill_[static_cast<size_t>(cell_of_[static_cast<size_t>(i)])]++);
    sorted_[slot] = i;
    sx_[slot] = px_[static_cast<size_t>(i)], sy_[slot] = py_[static_cast<size_t>(i)]; // cell order: contiguous scans
  }

  // Scanned in slot order, which is cell order: a particle's own cell after it and the cell to its right
  // are adjacent slots, and so are the three cells of the row above (left to right); two ranges a particle.
  const double h2 = p_.h * p_.h;
  size_t np = 0; // pairs so far; pairs_ only grows, room is made once a range, not once a pair
  auto scan = [&](size_t a, int32_t b0, int32_t b1) {
    const double xi = sx_[a], yi = sy_[a];
    if (b1 > b0 && pairs_.size() < np + static_cast<size_t>(b1 - b0))
      pairs_.resize(std::max(2 * pairs_.size(), np + static_cast<size_t>(b1 - b0)));
    for (size_t b = static_cast<size_t>(b0); b < static_cast<size_t>(b1); ++b) {
      const double ex = sx_[b] - xi, ey = sy_[b] - yi;
      const double r2 = ex * ex + ey * ey;
      if (r2 >= h2 || r2 < 1e-18) continue; // coincident particles have no axis: skipped this step
      const double r = std::sqrt(r2), w = 1.0 - r * inv;
      const int32_t j = sorted_[b];
      pairs_[np++] = {j, ex / r, ey / r, w};
    }
  };
  for (size_t a = 0; a < static_cast<size_t>(n_); ++a) {
    first_[a] = static_cast<int32_t>(np);
    const int32_t c = cell_of_[static_cast<size_t>(sorted_[a])], cx = c % nx, cy = c / nx;
    scan(a, static_cast<int32_t>(a) + 1, cell_start_[static_cast<size_t>(cx + 1 < nx ? c + 2 : c + 1)]);
    if (cy + 1 < ny) {
      const int32_t row = (cy + 1) * nx;
      scan(a, cell_start_[static_cast<size_t>(row + std::max(cx - 1, 0))],
           cell_start_[static_cast<size_t>(row + std::min(cx + 1, nx - 1) + 1)]);
    }
  }
  first_[static_cast<size_t>(n_)] = static_cast<int32_t>(np);
}

void Fluid::step(double dt, double gy, const double *x, const double *y, double *vx, double *vy) {
  const size_t n = static_cast<size_t>(n_);
  // One neighbour search and one pair geometry a step, on the positions predicted under gravity: what
  // the viscosity changes moves a particle by dt·Δv, a small fraction of h.
  predict(dt, gy, x, y, vx, vy);
  find_pairs();

  // Each loop below goes over the pairs slot by slot: a slot's pairs share their first particle, whose
  // velocity (or density) stays in a register meanwhile. No other pair touches it, so every sum is made
  // in the order of the pairs, as in one loop over them.

  // Viscosity and agitation on the relative normal velocity u of each pair, weights (1 − q)² and
  // (1 − q): du = −σ(1 − q)²·u·dt + √(2σ·dt)·v_T·(1 − q)·ξ, half to each particle. For one pair this
  // settles at ⟨u²⟩ = v_T² (fluctuation–dissipation).
  if (p_.sigma > 0.0) {
    const double kick = std::sqrt(2.0 * p_.sigma * dt) * p_.agitation;
    for (size_t a = 0; a < n; ++a) {
      const size_t i = static_cast<size_t>(sorted_[a]);
      double vxi = vx[i], vyi = vy[i];
      for (size_t k = static_cast<size_t>(first_[a]); k < static_cast<size_t>(first_[a + 1]); ++k) {
        const Pair &pr = pairs_[k];
        const size_t j = static_cast<size_t>(pr.j);
        const double u = (vx[j] - vxi) * pr.ex + (vy[j] - vyi) * pr.ey;
        const double du = -p_.sigma * pr.w * pr.w * u * dt + kick * pr.w * unit_noise(rng_);
        vxi -= 0.5 * du * pr.ex, vyi -= 0.5 * du * pr.ey;
        vx[j] += 0.5 * du * pr.ex, vy[j] += 0.5 * du * pr.ey;
      }
      vx[i] = vxi, vy[i] = vyi;
    }
  }

  // Density; pressure k(ρ − ρ0), never a pull.
  std::fill(rho_.begin(), rho_.end(), 0.0);
  for (size_t a = 0; a < n; ++a) {
    const size_t i = static_cast<size_t>(sorted_[a]);
    double rho_i = rho_[i];
    for (size_t k = static_cast<size_t>(first_[a]); k < static_cast<size_t>(first_[a + 1]); ++k) {
      const Pair &pr = pairs_[k];
      rho_i += pr.w * pr.w;
      rho_[static_cast<size_t>(pr.j)] += pr.w * pr.w;
    }
    rho_[i] = rho_i;
  }
  max_ratio_ = 0.0;
  for (size_t i = 0; i < n; ++i) {
    max_ratio_ = std::max(max_ratio_, rho_[i] / p_.rho0);
    rho_[i] = std::max(0.0, p_.k * (rho_[i] - p_.rho0)); // from here on: pressure [m/s²]
  }

  // Relaxation, Clavet's displacement summed over both ends of a pair: each end moves dt²·P̄·(1 − q)
  // along the pair's axis, P̄ the pair's mean pressure; the move, over dt, is a velocity change.
  const double half_dt = 0.5 * dt;
  for (size_t a = 0; a < n; ++a) {
    const size_t i = static_cast<size_t>(sorted_[a]);
    double vxi = vx[i], vyi = vy[i];
    for (size_t k = static_cast<size_t>(first_[a]); k < static_cast<size_t>(first_[a + 1]); ++k) {
      const Pair &pr = pairs_[k];
      const size_t j = static_cast<size_t>(pr.j);
      const double d = half_dt * (rho_[i] + rho_[j]) * pr.w;
      vxi -= d * pr.ex, vyi -= d * pr.ey;
      vx[j] += d * pr.ex, vy[j] += d * pr.ey;
    }
    vx[i] = vxi, vy[i] = vyi;
  }
}

} // namespace poursim
