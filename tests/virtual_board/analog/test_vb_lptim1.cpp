// SPDX-License-Identifier: MIT
// LPTIM1 against RM0440 section 33: reset values, ARROK after a write to ARR, the count of HSI16 / 128,
// and what the manual forbids (CFGR written while enabled) stopping the board by name.
#include "setup.hpp"

using namespace vbt;

int main() {
  Board b;
  CHECK(b.r("LPTIM1", 0x18) == 1u, "ARR reset 1");
  b.w("LPTIM1", 0x0C, 7u << 9);  // PRESC 111: /128, while disabled
  b.w("LPTIM1", 0x10, 1u);       // ENABLE
  b.w("LPTIM1", 0x18, 0xFFFFu);
  CHECK((b.r("LPTIM1", 0x00) & (1u << 4)) == 0u, "ARROK not at once");
  b.run_s(1e-6);
  CHECK((b.r("LPTIM1", 0x00) & (1u << 4)) != 0u, "ARROK after the synchronisation");
  b.w("LPTIM1", 0x10, 1u | (1u << 2));  // CNTSTRT
  b.run_s(1e-3);
  const uint32_t c = b.r("LPTIM1", 0x1C);
  CHECK(c == 125u, "1 ms of 16 MHz / 128: 125 counts, got %u", c);
  CHECK(b.link.stops.empty(), "no stop so far");
  b.w("LPTIM1", 0x0C, 0u);
  CHECK(!b.link.stops.empty() && b.link.stops[0].find("CFGR written while enabled") != std::string::npos,
        "CFGR while enabled stops the board");
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
