// SPDX-License-Identifier: MIT
// A board without a CPU for the analog models' tests: a time base at a fixed HCLK, the interrupt lines'
// levels, and the stop reasons; run_to() advances the models event by event as the board does.
#ifndef POUR_TEST_VB_ANALOG_HARNESS_HPP
#define POUR_TEST_VB_ANALOG_HARNESS_HPP

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "analog.hpp"
#include "models.hpp"

namespace vbt {

class Link : public vb::BoardLink {
 public:
  void set_irq(int irqn, bool level) override {
    if (level && !irq[irqn]) ++rises[irqn];
    irq[irqn] = level;
  }
  uint64_t cycles() const override { return now; }
  uint32_t hclk_hz() const override { return hz; }
  void stop(const std::string& reason) override { stops.push_back(reason); }
  void request_reset(const std::string& cause) override { resets.push_back(cause); }
  uint64_t now = 0;
  uint32_t hz = 170000000u;
  std::map<int, bool> irq;
  std::map<int, int> rises;
  std::vector<std::string> stops, resets;
};

struct Board {
  explicit Board(const vb::AnalogOptions& o = vb::AnalogOptions{}) : set(vb::make_analog_models(o)) {
    for (auto& p : set.peripherals) p->attach(&link);
    for (auto& p : set.peripherals) p->reset();
  }
  vb::Peripheral* find(const std::string& name) {
    for (auto& p : set.peripherals) if (p->name() == name) return p.get();
    return nullptr;
  }
  void w(const std::string& periph, uint32_t off, uint32_t v) {
    if (!find(periph)->write(off, 4, v)) { std::printf("write %s+0x%x refused\n", periph.c_str(), off); ok = false; }
  }
  uint32_t r(const std::string& periph, uint32_t off) {
    uint32_t v = 0;
    if (!find(periph)->read(off, 4, &v)) { std::printf("read %s+0x%x refused\n", periph.c_str(), off); ok = false; }
    return v;
  }
  // Run the models to cycle `target`, stopping at each model's next event as the board does.
  void run_to(uint64_t target) {
    for (;;) {
      uint64_t next = UINT64_MAX;
      for (auto& p : set.peripherals) next = std::min(next, p->next_event());
      if (next > target) break;
      link.now = std::max(link.now, next);
      for (auto& p : set.peripherals) p->advance();
    }
    link.now = target;
    for (auto& p : set.peripherals) p->advance();
  }
  void run_s(double s) { run_to(link.now + static_cast<uint64_t>(std::llround(s * link.hz))); }
  Link link;
  vb::AnalogSet set;
  bool ok = true;
};

inline int failures = 0;
#define CHECK(cond, ...)                                                      \
  do {                                                                        \
    if (!(cond)) {                                                            \
      std::printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);             \
      std::printf(__VA_ARGS__);                                               \
      std::printf("\n");                                                      \
      ++vbt::failures;                                                        \
    }                                                                         \
  } while (0)

}  // namespace vbt

#endif
