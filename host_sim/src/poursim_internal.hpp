// SPDX-License-Identifier: MIT
// Private helpers shared by libpoursim's sources.
#ifndef POURSIM_INTERNAL_HPP
#define POURSIM_INTERNAL_HPP

#include <cstddef>

#include "poursim/poursim.h"

namespace poursim {

// Formats into err (if any) and returns status.
int set_error(char *err, size_t err_len, int status, const char *fmt, ...) __attribute__((format(printf, 4, 5)));

// Radius of circle i: evenly spread over [radius_min, radius_max], the same set for every seed.
inline double particle_radius(const poursim_config_t *c, int i) {
  if (c->n_particles <= 1) return 0.5 * (c->radius_min + c->radius_max);
  return c->radius_min + (c->radius_max - c->radius_min) * i / (c->n_particles - 1);
}

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
