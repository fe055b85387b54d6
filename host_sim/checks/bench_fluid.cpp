// SPDX-License-Identifier: MIT
// The fluid layer alone, for comparing versions of it: 150 particles at the liquid's rest spacing in a
// 24 cm box with gravity (walls reflect them, no Box2D), 3,000 steps of Fluid::step, seven times; prints
// the fastest repetition's time per step and a checksum of the final positions (the same checksum = the
// same arithmetic). Run it pinned (taskset -c 1) and interleaved with the version it is compared with:
// on a shared machine one binary's time varies by ±10 % from run to run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "fluid.hpp"

int main(int argc, char **argv) {
  if (argc == 2 && std::strcmp(argv[1], "--help") == 0) {
    std::printf("usage: bench_fluid\n  times the fluid layer alone (150 particles, 7 x 3000 steps) and prints the\n"
                "  fastest repetition's time a step and a checksum of the final positions\n");
    return 0;
  }
  if (argc == 2 && std::strcmp(argv[1], "--version") == 0) {
    std::printf("bench_fluid %s\n", POUR_VERSION);
    return 0;
  }
  if (argc > 1) {
    std::fprintf(stderr, "bench_fluid: takes no arguments, got '%s' (see --help)\n", argv[1]);
    return 2;
  }
  constexpr size_t kN = 150;
  constexpr int kSteps = 3000, kReps = 7;
  constexpr double kSpacing = 0.019, kDt = 1e-3, kGravity = 9.81, kWidth = 0.24;
  poursim::FluidParams p;
  p.h = 1.8 * kSpacing;
  p.rho0 = poursim::fluid_rest_density(kSpacing, p.h);
  p.k = 2000.0;
  p.sigma = 20.0;
  p.agitation = 0.05;
  poursim::Fluid fluid;
  fluid.configure(p, static_cast<int>(kN), 7);
  std::vector<double> x(kN), y(kN), vx(kN, 0.0), vy(kN, 0.0);
  for (size_t i = 0; i < kN; ++i) x[i] = static_cast<double>(i % 12) * kSpacing, y[i] = static_cast<double>(i / 12) * kSpacing;
  double best = 1e9;
  for (int rep = 0; rep < kReps; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < kSteps; ++k) {
      fluid.step(kDt, -kGravity, x.data(), y.data(), vx.data(), vy.data());
      for (size_t i = 0; i < kN; ++i) {
        vy[i] -= kGravity * kDt;
        x[i] += vx[i] * kDt, y[i] += vy[i] * kDt;
        if (x[i] < 0.0) x[i] = 0.0, vx[i] = 0.5 * std::fabs(vx[i]);
        if (x[i] > kWidth) x[i] = kWidth, vx[i] = -0.5 * std::fabs(vx[i]);
        if (y[i] < 0.0) y[i] = 0.0, vy[i] = 0.5 * std::fabs(vy[i]);
      }
    }
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  double checksum = 0.0;
  for (size_t i = 0; i < kN; ++i) checksum += 1e3 * x[i] + y[i];
  std::printf("fluid layer alone: %.2f us a step (%zu particles, fastest of %d x %d steps); checksum %.10g\n",
              1e6 * best / kSteps, kN, kReps, kSteps, checksum);
  return 0;
}
