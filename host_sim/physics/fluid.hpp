// SPDX-License-Identifier: MIT
// The particle-fluid layer over the Box2D circles. Box2D keeps the circles' contacts with the buckets;
// this layer owns every circle–circle interaction:
//  - pressure from a local density estimate, as a pairwise push (the density relaxation of Clavet,
//    Beaudoin and Poulin 2005, without their near-pressure and cohesion);
//  - pairwise viscosity and a matching pairwise random agitation, a dissipative-particle-dynamics
//    thermostat (Español and Warren 1995): 150 particles at rest jam into a soft crystal with a yield
//    stress; agitation keeps them a liquid (docs/simulator.md has the measurements).
// Every interaction acts along a pair's axis with equal and opposite impulses, so momentum is conserved
// exactly. Neighbours come from a cell grid rebuilt each step: a step costs O(n).
#ifndef POURSIM_FLUID_HPP
#define POURSIM_FLUID_HPP

#include <cstdint>
#include <vector>

namespace poursim {

struct FluidParams {
  double h = 0.0;         // interaction radius [m]
  double rho0 = 0.0;      // rest density: Σ(1 − r/h)² over a particle's neighbours at rest [-]
  double k = 0.0;         // pressure stiffness [m/s²]
  double sigma = 0.0;     // pair viscosity [1/s]
  double agitation = 0.0; // thermal speed: RMS relative speed of an isolated pair at equilibrium [m/s]
};

// Σ(1 − r/h)² over the neighbours of one particle of a triangular lattice of spacing² area a particle
// [m]: the rest density that leaves the liquid, which settles into that packing, without pressure.
double fluid_rest_density(double spacing, double h);

class Fluid {
 public:
  void configure(const FluidParams &p, int n, uint64_t seed);
  // One step of dt: x, y are the positions [m] and vx, vy the velocities [m/s] after the previous step;
  // the velocities change in place. Gravity (0, gy) [m/s²] is left to the rigid-body step but enters the
  // prediction the density is measured on.
  void step(double dt, double gy, const double *x, const double *y, double *vx, double *vy);
  // Largest density over rest density after the last step (compression) [-].
  double max_density_ratio() const { return max_ratio_; }

 private:
  struct Pair {
    int32_t j;     // the other end; the first is the particle of the slot whose pairs these are (first_)
    double ex, ey; // unit vector from the first particle to j
    double w;      // 1 − r/h
  };
  void predict(double dt, double gy, const double *x, const double *y, const double *vx, const double *vy);
  void find_pairs();

  FluidParams p_{};
  int n_ = 0;
  uint64_t rng_ = 1;
  std::vector<double> px_, py_, sx_, sy_, rho_; // predicted positions; the same in cell order
  std::vector<int32_t> cell_of_, cell_start_, fill_, sorted_, first_; // first_[a]: slot a's first pair
  std::vector<Pair> pairs_; // slot a's pairs are [first_[a], first_[a + 1]); beyond first_[n] unused room
  double max_ratio_ = 0.0;
};

} // namespace poursim

#endif // POURSIM_FLUID_HPP
