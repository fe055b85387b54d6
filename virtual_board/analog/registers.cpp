// SPDX-License-Identifier: MIT
// The narrow accesses of every analog model, in one place (access.hpp's lanes).
#include "access.hpp"
#include "models.hpp"

namespace vb {

bool RegPeripheral::read(uint32_t offset, unsigned width, uint32_t* value) {
  uint32_t w = 0;
  if (!read32(offset & ~3u, &w)) return false;
  *value = lane_read(w, offset, width);
  return true;
}

bool RegPeripheral::write(uint32_t offset, unsigned width, uint32_t value) {
  const uint32_t a = offset & ~3u;
  if (width < 4u) {
    if (words_only_) return false;  // RM0440: this peripheral's registers are accessed by words only
    uint32_t cur = 0;
    if (!read32(a, &cur)) return false;
    value = lane_merge(merge_base(a, cur), offset, width, value);
  }
  return write32(a, value);
}

}  // namespace vb
