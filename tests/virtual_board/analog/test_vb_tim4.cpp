// SPDX-License-Identifier: MIT
// TIM4 in encoder mode against RM0440 29.3.22: x4 counting on both inputs, an inverted input reversing the
// count, x2 on one input, the 16-bit wrap with UIF, nothing counted with CEN clear; reset values.
#include "setup.hpp"

using namespace vbt;

int main() {
  Board b;
  CHECK(b.r("TIM4", 0x2C) == 0xFFFFFFFFu, "ARR reset 0xFFFFFFFF (the crate's SVD)");
  CHECK(b.r("TIM4", 0x24) == 0u, "CNT reset 0");
  b.w("TIM4", 0x08, 3u);                     // SMS 011: both inputs' edges
  b.w("TIM4", 0x18, 1u | (1u << 8));         // CC1S = CC2S = 01
  b.set.tim4->edges(10);
  CHECK(b.r("TIM4", 0x24) == 0u, "CEN clear: no count");
  b.w("TIM4", 0x00, 1u);
  b.set.tim4->edges(10);
  CHECK(b.r("TIM4", 0x24) == 10u, "x4: 10 edges, 10 counts: %u", b.r("TIM4", 0x24));
  b.set.tim4->edges(-20);
  CHECK(b.r("TIM4", 0x24) == 0xFFF6u, "wraps below 0 to 0xFFF6: 0x%x", b.r("TIM4", 0x24));
  CHECK((b.r("TIM4", 0x10) & 1u) != 0u, "UIF at the wrap");
  CHECK((b.r("TIM4", 0x00) & (1u << 4)) != 0u, "DIR: counting down");
  b.set.tim4->edges(20);
  CHECK(b.r("TIM4", 0x24) == 10u, "wraps back up: %u", b.r("TIM4", 0x24));
  b.w("TIM4", 0x20, 1u << 1);                // CC1P: TI1 inverted
  b.set.tim4->edges(4);
  CHECK(b.r("TIM4", 0x24) == 6u, "an inverted input counts the other way: %u", b.r("TIM4", 0x24));
  b.w("TIM4", 0x20, 0u);
  b.w("TIM4", 0x08, 2u);                     // SMS 010: TI1's edges only
  b.set.tim4->edges(8);
  CHECK(b.r("TIM4", 0x24) == 10u, "x2: 8 edges of both inputs, 4 counts: %u", b.r("TIM4", 0x24));
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
