// SPDX-License-Identifier: MIT
// Private helpers shared by libpoursim's sources.
#ifndef POURSIM_INTERNAL_HPP
#define POURSIM_INTERNAL_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "poursim/poursim.h"

namespace poursim {

// Formats into err (if any) and returns status.
int set_error(char *err, size_t err_len, int status, const char *fmt, ...) __attribute__((format(printf, 4, 5)));

// Particles at the free surface and along the walls lack neighbours on one side, so they settle closer
// than the bulk's rest spacing: with the bare spacing the liquid stood at 0.920–0.925 of fill_depth over
// fills of 80–120 %. The rest spacing is widened by this factor so that the liquid settles to fill_depth
// (test_world_FillDepthSetsTheLevelTheLiquidSettlesTo pins it within 3 %).
constexpr double kBoundaryPacking = 1.0415;

// Rest spacing of the liquid's particles: the fill's cross-section shared by n_particles [m].
inline double particle_spacing(const poursim_config_t *c) {
  return kBoundaryPacking * std::sqrt(c->bucket_inner_width * c->fill_depth / c->n_particles);
}

// Radius of every circle (its contacts with the buckets) [m].
inline double particle_radius(const poursim_config_t *c) { return c->fluid_contact_radius * particle_spacing(c); }

// All the liquid: the fill of a round bucket of the inner width [kg], and its volume [L].
inline double liquid_mass(const poursim_config_t *c) {
  return c->liquid_density * c->fill_depth * M_PI * 0.25 * c->bucket_inner_width * c->bucket_inner_width;
}
inline double liquid_litres(const poursim_config_t &c) {
  const double r = 0.5 * c.bucket_inner_width;
  return 1000.0 * M_PI * r * r * c.fill_depth;
}

// The config of the episode of seed: each rand_* key draws its parameters uniformly in ± its value
// around c's (relative or absolute, as poursim.h says); c itself when every rand_* key is 0.
poursim_config_t draw_episode_config(const poursim_config_t &c, uint32_t seed);

// Deterministic PRNG (splitmix64): the same stream on every platform.
struct Rng {
  unsigned long long s;
  explicit Rng(unsigned long long seed) : s(seed) {}
  unsigned long long next() {
    unsigned long long z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); } // [0, 1)
};

} // namespace poursim

#endif // POURSIM_INTERNAL_HPP
