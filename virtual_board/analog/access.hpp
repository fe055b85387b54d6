// SPDX-License-Identifier: MIT
// Byte and half-word accesses to the 32-bit registers of the analog models: a narrow read returns its lanes
// of the word; a narrow write merges its lanes into the word as it reads now (RM0440 allows half-word and
// word accesses to the timers, word accesses elsewhere; the models accept both and say so here).
#ifndef POUR_VB_ANALOG_ACCESS_HPP
#define POUR_VB_ANALOG_ACCESS_HPP

#include <cstdint>

namespace vb {

inline uint32_t lane_mask(uint32_t offset, unsigned width) {
  const uint32_t shift = (offset & 3u) * 8u;
  return (width >= 4u ? 0xFFFFFFFFu : ((1u << (width * 8u)) - 1u)) << shift;
}
inline uint32_t lane_read(uint32_t word, uint32_t offset, unsigned width) {
  return (word & lane_mask(offset, width)) >> ((offset & 3u) * 8u);
}
inline uint32_t lane_merge(uint32_t word, uint32_t offset, unsigned width, uint32_t value) {
  const uint32_t m = lane_mask(offset, width);
  return (word & ~m) | ((value << ((offset & 3u) * 8u)) & m);
}
inline uint32_t field(uint32_t v, unsigned pos, unsigned width) { return (v >> pos) & ((1u << width) - 1u); }
inline bool bit(uint32_t v, unsigned pos) { return ((v >> pos) & 1u) != 0u; }

}  // namespace vb

#endif
