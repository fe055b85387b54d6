// SPDX-License-Identifier: MIT
#include "profile.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

namespace vb {

namespace {
uint32_t u32(const std::vector<uint8_t>& b, size_t o) {
  return uint32_t{b[o]} | uint32_t{b[o + 1]} << 8 | uint32_t{b[o + 2]} << 16 | uint32_t{b[o + 3]} << 24;
}
uint16_t u16(const std::vector<uint8_t>& b, size_t o) { return static_cast<uint16_t>(b[o] | b[o + 1] << 8); }
constexpr uint32_t kFlashBase = 0x08000000u, kFlashSize = 128u * 1024u;
}  // namespace

std::string Profiler::load(const std::string& elf_path, const std::vector<std::string>& functions) {
  std::ifstream f(elf_path, std::ios::binary);
  if (!f) return "--profile: cannot read " + elf_path;
  const std::vector<uint8_t> b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  // ELF32 (the board has checked the file's class, machine and segments): the section headers, then each
  // SHT_SYMTAB with its string table (sh_link).
  if (b.size() < 52) return "--profile: " + elf_path + " has no ELF header";
  const uint32_t shoff = u32(b, 32);
  const uint16_t shentsize = u16(b, 46), shnum = u16(b, 48);
  if (shnum == 0 || shentsize < 40 || shoff + static_cast<uint64_t>(shentsize) * shnum > b.size()) {
    return "--profile: " + elf_path + " has no section headers (a stripped image has no symbols to name the handlers)";
  }
  for (uint16_t i = 0; i < shnum; ++i) {
    const size_t sh = shoff + static_cast<size_t>(i) * shentsize;
    if (u32(b, sh + 4) != 2u) continue;  // SHT_SYMTAB
    const uint32_t off = u32(b, sh + 16), size = u32(b, sh + 20), link = u32(b, sh + 24);
    if (link >= shnum || off + static_cast<uint64_t>(size) > b.size()) return "--profile: a bad symbol table";
    const size_t str_sh = shoff + static_cast<size_t>(link) * shentsize;
    const uint32_t str_off = u32(b, str_sh + 16), str_size = u32(b, str_sh + 20);
    if (str_off + static_cast<uint64_t>(str_size) > b.size()) return "--profile: a bad string table";
    for (uint32_t s = 0; s + 16u <= size; s += 16u) {
      const uint32_t name = u32(b, off + s), value = u32(b, off + s + 4), sz = u32(b, off + s + 8);
      if ((b[off + s + 12] & 0xFu) != 2u || name >= str_size) continue;  // STT_FUNC only
      const char* p = reinterpret_cast<const char*>(b.data()) + str_off + name;
      symbols_[value & ~1u] = {sz, std::string(p, strnlen(p, str_size - name))};
    }
  }
  if (symbols_.empty()) return "--profile: " + elf_path + " has no function symbols";
  for (const std::string& want : functions) {
    for (const auto& [start, s] : symbols_) {
      if (s.second == want || s.second.rfind(want + ".", 0) == 0) {
        entries_[start] = funcs_.size();
        funcs_.push_back(Func{s.second});
      }
    }
  }
  return {};
}

std::string Profiler::symbol_at(uint32_t a) const {
  if (a < kFlashSize) a += kFlashBase;  // the alias at 0 (boot from main flash)
  auto it = symbols_.upper_bound(a);
  if (it == symbols_.begin()) return "?";
  --it;
  if (a - it->first < std::max<uint32_t>(it->second.first, 2u)) return it->second.second;
  return "?";
}

void Profiler::block(uc_engine* uc, uint32_t address, uint32_t n, size_t depth) {
  if (depth == 0) {
    if (!calls_.empty() && address == calls_.back().ret) {
      uint32_t sp = 0;
      uc_reg_read(uc, UC_ARM_REG_SP, &sp);
      if (sp == calls_.back().sp) {
        const Call c = calls_.back();
        calls_.pop_back();
        Func& fn = funcs_[c.func];
        const uint64_t incl = executed_ - c.e0, isr = in_isr_ - c.isr0, excl = incl - isr;
        ++fn.calls;
        fn.incl_sum += incl;
        fn.excl_sum += excl;
        fn.incl_max = std::max(fn.incl_max, incl);
        fn.excl_max = std::max(fn.excl_max, excl);
        fn.preempted += isr > 0 ? 1u : 0u;
      }
    }
    const uint32_t a = address < kFlashSize ? address + kFlashBase : address;
    auto it = entries_.find(a);
    if (it != entries_.end()) {
      uint32_t sp = 0, lr = 0;
      uc_reg_read(uc, UC_ARM_REG_SP, &sp);
      uc_reg_read(uc, UC_ARM_REG_LR, &lr);
      calls_.push_back(Call{it->second, lr & ~1u, sp, executed_, in_isr_});
    }
  }
  executed_ += n;
  if (depth > 0) in_isr_ += n;
}

void Profiler::exception_entry(int exc, uint32_t handler, uint32_t overhead) {
  Exc& e = excs_[exc];
  if (e.handler.empty()) e.handler = symbol_at(handler);
  if (!frames_.empty()) ++e.preempted;
  frames_.push_back(Frame{exc, executed_, 0, overhead});
}

void Profiler::exception_return(uint32_t overhead) {
  if (frames_.empty()) return;
  const Frame f = frames_.back();
  frames_.pop_back();
  Exc& e = excs_[f.exc];
  e.overhead = f.entry_overhead + overhead;
  const uint64_t incl = executed_ - f.e0, self = incl - f.nested;
  ++e.entries;
  e.self_sum += self;
  e.self_max = std::max(e.self_max, self);
  e.incl_max = std::max(e.incl_max, incl);
  if (!frames_.empty()) frames_.back().nested += incl;
}

void Profiler::reset() {
  frames_.clear();
  calls_.clear();
}

void Profiler::report(std::FILE* out, unsigned cpi_milli, uint32_t hclk_hz, double emulated_s) const {
  const double cpi = cpi_milli / 1000.0;
  const double period = hclk_hz * 50e-6;  // the current loop's 50 us (20 kHz) in cycles
  std::fprintf(out,
               "profile: instructions the virtual board executed (idle skipped); cycles are a model: instructions x CPI %.3f"
               " + the exception's entry and return (12 + 10 cycles); HCLK %.1f MHz, the 50 us period %.0f cycles\n",
               cpi, hclk_hz / 1e6, period);
  for (const auto& [exc, e] : excs_) {
    if (e.entries == 0) continue;
    const double mean = static_cast<double>(e.self_sum) / static_cast<double>(e.entries);
    const double c_mean = mean * cpi + e.overhead, c_worst = static_cast<double>(e.self_max) * cpi + e.overhead;
    std::fprintf(out,
                 "profile: exception %d (%s%d) %s: %llu entries, instructions mean %.1f worst %llu (with what nested in it: "
                 "worst %llu); cycles mean %.0f worst %.0f = %.1f %% / %.1f %% of the 50 us period; %llu entries nested in "
                 "another exception; %.2f kHz, %.1f %% of the core\n",
                 exc, exc >= 16 ? "IRQ " : "system ", exc >= 16 ? exc - 16 : exc, e.handler.c_str(),
                 (unsigned long long)e.entries, mean, (unsigned long long)e.self_max, (unsigned long long)e.incl_max, c_mean,
                 c_worst, 100.0 * c_mean / period, 100.0 * c_worst / period, (unsigned long long)e.preempted,
                 emulated_s > 0 ? static_cast<double>(e.entries) / emulated_s / 1e3 : 0.0,
                 emulated_s > 0 ? 100.0 * c_mean * static_cast<double>(e.entries) / (emulated_s * hclk_hz) : 0.0);
  }
  for (const Func& fn : funcs_) {
    if (fn.calls == 0) {
      std::fprintf(out, "profile: function %s: 0 calls\n", fn.name.c_str());
      continue;
    }
    const double n = static_cast<double>(fn.calls);
    std::fprintf(out,
                 "profile: function %s: %llu calls, instructions excluding interrupts mean %.1f worst %llu, including them "
                 "mean %.1f worst %llu; %llu calls preempted\n",
                 fn.name.c_str(), (unsigned long long)fn.calls, static_cast<double>(fn.excl_sum) / n,
                 (unsigned long long)fn.excl_max, static_cast<double>(fn.incl_sum) / n, (unsigned long long)fn.incl_max,
                 (unsigned long long)fn.preempted);
  }
}

}  // namespace vb
