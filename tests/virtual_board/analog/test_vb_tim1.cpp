// SPDX-License-Identifier: MIT
// TIM1 against RM0440 section 28: reset values, the centre-aligned counter's period and direction, TRGO2's
// instant, the preload of CCRx at the update event, the break from the comparators.
#include "setup.hpp"

using namespace vbt;

namespace {
std::vector<uint64_t> edges;
void sink(void*, uint64_t c) { edges.push_back(c); }
}  // namespace

int main() {
  {
    Board b;
    CHECK(b.r("TIM1", T1_ARR) == 0xFFFFu, "ARR reset 0xFFFF, got 0x%x", b.r("TIM1", T1_ARR));
    CHECK(b.r("TIM1", T1_AF1) == 0u, "AF1 reset 0 (the crate's SVD)");
    CHECK(b.r("TIM1", T1_CR1) == 0u && b.r("TIM1", T1_BDTR) == 0u, "CR1, BDTR reset 0");
    uint32_t v = 0;
    CHECK(!b.set.tim1->read(0x70, 4, &v), "an offset with no register is refused");
  }
  {
    Board b;
    b.set.tim1->add_trgo2_sink(sink, nullptr);
    const uint64_t t0 = b.link.now;
    tim1_pwm(b, 1000, 2000, 3000);
    b.run_to(t0 + 100);
    CHECK(b.r("TIM1", T1_CNT) == 100u, "counting up: CNT %u", b.r("TIM1", T1_CNT));
    b.run_to(t0 + ARR_20KHZ + 50);
    CHECK(b.r("TIM1", T1_CNT) == ARR_20KHZ - 50u, "counting down from the top: CNT %u", b.r("TIM1", T1_CNT));
    CHECK((b.r("TIM1", T1_CR1) & (1u << 4)) != 0u, "DIR set counting down");
    b.run_to(t0 + 10 * 2 * ARR_20KHZ + 10);
    CHECK(edges.size() == 10u, "one TRGO2 a period over 10 periods: %zu", edges.size());
    for (size_t k = 1; k < edges.size(); ++k) {
      CHECK(edges[k] - edges[k - 1] == 2u * ARR_20KHZ, "period 8500 cycles = 50 us at 170 MHz: %llu",
            static_cast<unsigned long long>(edges[k] - edges[k - 1]));
    }
    // OC4REF (PWM1) rises counting down where CNT = CCR4 = ARR - 1: one tick after the top.
    CHECK(!edges.empty() && edges[0] - t0 == ARR_20KHZ + 1u, "TRGO2 one tick past the top: %llu",
          static_cast<unsigned long long>(edges.empty() ? 0 : edges[0] - t0));
    CHECK(std::fabs(b.set.tim1->duty(0) - 1000.0 / ARR_20KHZ) < 1e-9, "duty CCR1/ARR");
    // Preload: a new CCR1 waits for the next update event (the next over- or underflow).
    const uint64_t p = b.link.now;  // 10 ticks into a period
    b.w("TIM1", T1_CCR1, 3000);
    CHECK(std::fabs(b.set.tim1->duty(0) - 1000.0 / ARR_20KHZ) < 1e-9, "CCR1 preloaded: old duty until the update");
    b.run_to(p + ARR_20KHZ);
    CHECK(std::fabs(b.set.tim1->duty(0) - 3000.0 / ARR_20KHZ) < 1e-9, "the update loaded CCR1");
    CHECK(b.set.tim1->deadtime_ticks() == 136u, "DTG 0x84: 136 ticks = 800 ns");
  }
  {
    // The update interrupt (TIM1_UP, table 97 position 25): each over- and underflow in centre-aligned mode
    // with RCR = 0, every second one with RCR = 1 (RM0440 28.3.3).
    for (uint32_t rcr : {0u, 1u}) {
      Board b;
      b.w("TIM1", 0x30, rcr);
      tim1_pwm(b, 0, 0, 0);
      b.w("TIM1", T1_DIER, 1u);
      int rises = 0;
      for (int n = 0; n < 40; ++n) {
        b.run_s(2.5e-6);
        if (b.link.irq[vb::IRQ_TIM1_UP]) { ++rises; b.w("TIM1", T1_SR, ~1u); }
      }
      // 100 us = 2 periods: 4 update events with RCR = 0, 2 with RCR = 1
      CHECK(rises == (rcr == 0u ? 4 : 2), "RCR %u: %d update interrupts in two periods", rcr, rises);
    }
  }
  {
    // Narrow accesses: a half-word to TIM1 (RM0440 28.6: half-word and word), refused by the ADC (words only).
    Board b;
    CHECK(b.set.tim1->write(T1_CCR1, 2, 0x1234u), "half-word write to CCR1");
    uint32_t v = 0;
    CHECK(b.set.tim1->read(T1_CCR1, 2, &v) && v == 0x1234u, "half-word read back: 0x%x", v);
    CHECK(b.set.tim1->read(T1_ARR + 1, 1, &v) && v == 0xFFu, "a byte of ARR: 0x%x", v);
    CHECK(!b.set.adc1->write(A_CR, 2, 0u), "a half-word write to the ADC is refused");
  }
  {
    // BDTR DTG's other ranges (RM0440 28.6.21): 0b10xxxxxx: (64 + x) x 2.
    Board b;
    b.w("TIM1", T1_BDTR, 0x80u | 5u);
    CHECK(b.set.tim1->deadtime_ticks() == 138u, "DTG 0x85: (64 + 5) x 2 = 138, got %u", b.set.tim1->deadtime_ticks());
  }
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
