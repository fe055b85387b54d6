// SPDX-License-Identifier: MIT
// The virtual B-G431B-ESC1: pour_firmware.elf on Unicorn's Cortex-M4 (QEMU's TCG CPU as a library), with
// the STM32G431CB's memory map (RM0440 §2.2, table 4), the core's NVIC, SCB and SysTick (ARMv7-M ARM B3),
// M-profile exception entry and return (B1.5.6, B1.5.8; Unicorn does not model them), and a lockstep time
// base: instructions x CPI give cycles, the core runs at most to the next model event, and WFI or a branch
// to itself skips to that event.
#include "board.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <thread>

namespace vb {

namespace {
constexpr uint32_t kFlashBase = 0x08000000u, kFlashSize = 128u * 1024u;
constexpr uint32_t kDataPages = 0x0801F000u;  // pages 62 and 63 (params, calibration): through the FLASH model
constexpr uint32_t kSramBase = 0x20000000u, kSramSize = 32u * 1024u;  // SRAM1 16 KB + SRAM2 6 KB + CCM alias 10 KB
constexpr uint32_t kCcmBase = 0x10000000u, kCcmSize = 10u * 1024u, kCcmAlias = 0x5800u;
constexpr uint32_t kScs = 0xE000E000u;
constexpr int kSysTick = 15, kNmi = 2, kHardFault = 3;
}  // namespace

Board::Board(const Options& o) : opt_(o), rcc_(this), iwdg_(this), flash_(this, flash_mem_.data(), kFlashSize), fdcan_(this), sramcan_(&fdcan_) {}

Board::~Board() {
  if (uc_ != nullptr) uc_close(uc_);
  if (can_fd_ >= 0) close(can_fd_);
}

uint64_t Board::now_ps() const {
  return time_ps_ + static_cast<uint64_t>((unsigned __int128)(cycles() - time_cycles_) * 1000000000000ull / hclk_);
}

uint64_t Board::cycles_until_ps(uint64_t t) const {
  const uint64_t now = now_ps();
  if (t <= now) return 0;
  const unsigned __int128 c = (unsigned __int128)(t - now) * hclk_ + 999999999999ull;
  return (uint64_t)(c / 1000000000000ull);
}

uint64_t Board::cycles() const { return insns_ * opt_.cpi_milli / 1000u; }

void Board::set_irq(int irqn, bool level) {
  if (irqn < 0 || irqn >= kIrqs) return;
  if (level && !irq_level_[irqn]) pend(16 + irqn);
  irq_level_[irqn] = level;
}

void Board::stop(const std::string& reason) {
  if (stopped_.empty()) {
    uint32_t pc = 0;
    uc_reg_read(uc_, UC_ARM_REG_PC, &pc);
    char b[64];
    std::snprintf(b, sizeof b, " (pc 0x%08x, t %.3f ms)", pc, static_cast<double>(now_ps()) / 1e9);
    stopped_ = reason + b;
  }
  uc_emu_stop(uc_);
}

void Board::request_reset(const std::string& cause) {
  reset_cause_ = cause;
  uc_emu_stop(uc_);
}

void Board::pend(int exc) {
  pending_[exc] = true;
  check_irq_ = true;
}

int Board::priority(int exc) const {
  if (exc == 1) return -3;
  if (exc == kNmi) return -2;
  if (exc == kHardFault) return -1;
  uint8_t p = 0;
  if (exc >= 16) p = ipr_[exc - 16];
  else p = shpr_[exc - 4];
  const unsigned group_shift = prigroup_ + 1u;  // ARMv7-M B1.5.4: bits above PRIGROUP are the group priority
  return static_cast<int>((p & 0xF0u) >> group_shift << group_shift);
}

bool Board::enabled(int exc) const {
  if (exc < 16) return true;
  return (iser_[(exc - 16) / 32] >> ((exc - 16) % 32)) & 1u;
}

int Board::best_pending() const {
  int best = -1, bp = 1000;
  for (int e = 1; e < 16 + kIrqs; ++e) {
    if (pending_[e] && enabled(e) && priority(e) < bp) {
      best = e;
      bp = priority(e);
    }
  }
  return best;
}

int Board::execution_priority() {
  int p = 256;
  for (int e : active_) p = std::min(p, priority(e));
  uint32_t primask = 0, basepri = 0;
  uc_reg_read(uc_, UC_ARM_REG_PRIMASK, &primask);
  uc_reg_read(uc_, UC_ARM_REG_BASEPRI, &basepri);
  if (basepri & 0xF0u) p = std::min<int>(p, static_cast<int>(basepri & 0xF0u) >> (prigroup_ + 1u) << (prigroup_ + 1u));
  if (primask & 1u) p = std::min(p, 0);
  return p;
}

void Board::hook_block(uc_engine* uc, uint64_t address, uint32_t size, void* user) {
  Board* b = static_cast<Board*>(user);
  // Stops asked for inside an access end the slice here, after the accessing instruction retired: a stop
  // inside the MMIO callback would resume at the access and repeat it.
  if (b->insns_ >= b->slice_end_ || b->stop_soon_) {
    uc_emu_stop(uc);
    return;
  }
  const uint64_t key = address << 8 | size;
  auto it = b->block_insns_.find(key);
  uint32_t n;
  if (it == b->block_insns_.end()) {
    std::vector<uint16_t> hw(size / 2u + 1u);
    uc_mem_read(uc, address, hw.data(), size);
    n = 0;
    bool self_loop = false;
    for (uint32_t i = 0; i < size / 2u; ++i, ++n) {
      const uint16_t h = hw[i];
      if (size == 2u && h == 0xE7FEu) self_loop = true;  // b . : an idle loop
      if ((h >> 11) >= 0x1Du) ++i;                       // a 32-bit Thumb-2 instruction
    }
    n = self_loop ? 0x80000000u | n : n;
    b->block_insns_[key] = n;
  } else {
    n = it->second;
  }
  if (n & 0x80000000u) {
    b->idle_ = true;
    uc_emu_stop(uc);
    return;
  }
  if (b->check_irq_) {
    const int e = b->best_pending();
    if (e < 0) {
      b->check_irq_ = false;
    } else if (b->priority(e) < b->execution_priority()) {
      uc_emu_stop(uc);
      return;
    }
  }
  b->insns_ += n;
  if (b->profiler_) b->profiler_->block(uc, static_cast<uint32_t>(address), n, b->active_.size());
}

void Board::hook_intr(uc_engine* uc, uint32_t intno, void* user) {
  Board* b = static_cast<Board*>(user);
  b->intno_ = static_cast<int>(intno);
  uc_emu_stop(uc);
}

bool Board::hook_unmapped(uc_engine* uc, uc_mem_type type, uint64_t address, int size, int64_t value, void* user) {
  (void)uc;
  (void)size;
  (void)value;
  Board* b = static_cast<Board*>(user);
  const std::string name = svd_name_at(static_cast<uint32_t>(address));
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s of unmapped address 0x%08llx", type == UC_MEM_WRITE_UNMAPPED ? "write"
                                                                  : type == UC_MEM_FETCH_UNMAPPED ? "fetch"
                                                                                                  : "read",
                (unsigned long long)address);
  b->stop(std::string(buf) + (name.empty() ? " (no peripheral there in RM0440 table 4)" : " in " + name + " (no model)"));
  return false;
}

// One 4 KB page of MMIO, dispatching each access to the window's model.
uint64_t Board::mmio_read(uc_engine* uc, uint64_t offset, unsigned size, void* user) {
  (void)uc;
  auto* p = static_cast<MmioPage*>(user);
  const uint32_t addr = p->base + static_cast<uint32_t>(offset);
  uint32_t v = 0;
  if (!p->board->access(addr, size, false, &v)) return 0;
  return v;
}

void Board::mmio_write(uc_engine* uc, uint64_t offset, unsigned size, uint64_t value, void* user) {
  (void)uc;
  auto* p = static_cast<MmioPage*>(user);
  uint32_t v = static_cast<uint32_t>(value);
  p->board->access(p->base + static_cast<uint32_t>(offset), size, true, &v);
}

bool Board::access(uint32_t addr, unsigned size, bool write, uint32_t* v) {
  for (Peripheral* m : models_) {
    if (addr >= m->base() && addr - m->base() < m->size()) {
      const uint32_t off = addr - m->base();
      // A peripheral with its bus clock off reads 0 and ignores writes: a driver that forgot the enable.
      for (const auto& g : gates_) {
        if (g.model == m && !rcc_.enabled(g.enr, g.bit)) {
          stop(std::string(write ? "write to " : "read of ") + m->name() + " with its clock off in RCC");
          return false;
        }
      }
      const bool ok = write ? m->write(off, size, *v) : m->read(off, size, v);
      if (!ok) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s 0x%08x: offset 0x%03x of %s, a register no model covers", write ? "write" : "read",
                      addr, off, m->name().c_str());
        stop(buf);
        return false;
      }
      if (write) {
        check_irq_ = true;
        const uint32_t h = rcc_.hclk_hz();
        if (h != hclk_) set_hclk(h);
        if (flash_.stall_until_ps > now_ps()) {
          stall_ = true;
          stop_soon_ = true;
        }
      }
      if (flash_.nmi_pending) {
        flash_.nmi_pending = false;
        pend(kNmi);
      }
      return true;
    }
  }
  const std::string name = svd_name_at(addr);
  char buf[128];
  std::snprintf(buf, sizeof buf, "%s 0x%08x", write ? "write to" : "read of", addr);
  stop(std::string(buf) + (name.empty() ? " (reserved in RM0440 table 4)" : " in " + name + " (no model)"));
  return false;
}

void Board::set_hclk(uint32_t h) {
  time_ps_ = now_ps();
  time_cycles_ = cycles();
  hclk_ = h;
}

// The System Control Space (ARMv7-M B3.2, B3.3, B3.4): SysTick, NVIC, SCB.
bool Scs::read(uint32_t off, unsigned width, uint32_t* value) {
  Board& b = *board_;
  uint32_t v = 0;
  const uint32_t w = off & ~3u;
  if (w == 0x010) {
    b.systick_advance();
    v = b.syst_csr_ | (b.syst_countflag_ ? 1u << 16 : 0u);
    b.syst_countflag_ = false;
  } else if (w == 0x014) v = b.syst_rvr_;
  else if (w == 0x018) { b.systick_advance(); v = b.syst_cvr_; }
  else if (w == 0x01C) v = 0x40000000u | (b.hclk_ / 8u / 100u - 1u);  // CALIB: no exact 10 ms reference
  else if (w >= 0x100 && w < 0x110) v = b.iser_[(w - 0x100) / 4];
  else if (w >= 0x180 && w < 0x190) v = b.iser_[(w - 0x180) / 4];
  else if ((w >= 0x200 && w < 0x210) || (w >= 0x280 && w < 0x290)) {
    const uint32_t base = (w & 0xF) * 8u;
    for (uint32_t i = 0; i < 32 && base + i < Board::kIrqs; ++i) v |= (b.pending_[16 + base + i] ? 1u : 0u) << i;
  } else if (w >= 0x300 && w < 0x310) {
    for (int e : b.active_) if (e >= 16 && (e - 16) / 32 == static_cast<int>((w - 0x300) / 4)) v |= 1u << ((e - 16) % 32);
  } else if (w >= 0x400 && w < 0x400 + Board::kIrqs) {
    std::memcpy(&v, &b.ipr_[w - 0x400], 4);
  } else if (w == 0xD00) v = 0x410FC241u;  // CPUID: Cortex-M4 r0p1 (the STM32G431's, RM0440 §46 / PM0214)
  else if (w == 0xD04) v = (b.active_.empty() ? 0u : static_cast<uint32_t>(b.active_.back())) |
                           (b.pending_[kSysTick] ? 1u << 26 : 0u) | (b.pending_[14] ? 1u << 28 : 0u);
  else if (w == 0xD08) v = b.vtor_;
  else if (w == 0xD0C) v = 0xFA050000u | (b.prigroup_ << 8);
  else if (w == 0xD10) v = b.scr_;
  else if (w == 0xD14) v = b.ccr_;
  else if (w >= 0xD18 && w < 0xD24) std::memcpy(&v, &b.shpr_[w - 0xD18], 4);
  else if (w == 0xD24 || w == 0xD28 || w == 0xD2C || w == 0xD34 || w == 0xD38) v = 0;
  else if (w == 0xD88) v = b.cpacr_;
  else return false;
  *value = width == 4 ? v : (v >> (8u * (off & 3u))) & ((1u << (8u * width)) - 1u);
  return true;
}

bool Scs::write(uint32_t off, unsigned width, uint32_t value) {
  Board& b = *board_;
  const uint32_t w = off & ~3u;
  if (width != 4u && !(w >= 0x400 && w < 0x400 + Board::kIrqs) && !(w >= 0xD18 && w < 0xD24)) return false;
  if (w == 0x010) {
    b.systick_advance();
    if ((value & 1u) && !(value & 4u)) {
      b.stop("SysTick: CLKSOURCE = 0 (HCLK / 8) is not modelled");
      return true;
    }
    b.syst_csr_ = value & 7u;
    b.syst_base_cycles_ = b.cycles();
  } else if (w == 0x014) b.syst_rvr_ = value & 0xFFFFFFu;
  else if (w == 0x018) { b.systick_advance(); b.syst_cvr_ = 0; b.syst_countflag_ = false; }
  else if (w >= 0x100 && w < 0x110) b.iser_[(w - 0x100) / 4] |= value;
  else if (w >= 0x180 && w < 0x190) b.iser_[(w - 0x180) / 4] &= ~value;
  else if (w >= 0x200 && w < 0x210) {
    for (uint32_t i = 0; i < 32; ++i) if ((value >> i & 1u) && (w - 0x200) * 8u + i < Board::kIrqs) b.pend(static_cast<int>(16u + (w - 0x200) * 8u + i));
  } else if (w >= 0x280 && w < 0x290) {
    for (uint32_t i = 0; i < 32; ++i) if ((value >> i & 1u) && (w - 0x280) * 8u + i < Board::kIrqs) b.pending_[16 + (w - 0x280) * 8 + i] = false;
  } else if (w >= 0x400 && w < 0x400 + Board::kIrqs) {
    std::memcpy(&b.ipr_[off - 0x400], &value, width);
  } else if (w == 0xD04) {
    if (value & (1u << 26)) b.pend(kSysTick);
    if (value & (1u << 25)) b.pending_[kSysTick] = false;
    if (value & (1u << 28)) b.pend(14);
    if (value & (1u << 31)) b.pend(kNmi);
  } else if (w == 0xD08) b.vtor_ = value & 0xFFFFFE00u;
  else if (w == 0xD0C) {
    if ((value >> 16) != 0x05FAu) return true;  // without VECTKEY the write is ignored (B3.2.6)
    b.prigroup_ = (value >> 8) & 7u;
    if (value & 4u) b.request_reset("SCB AIRCR SYSRESETREQ");
  } else if (w == 0xD10) b.scr_ = value;
  else if (w == 0xD14) b.ccr_ = value;
  else if (w >= 0xD18 && w < 0xD24) std::memcpy(&b.shpr_[off - 0xD18], &value, width);
  else if (w == 0xD88) {
    if (value & 0x00F00000u) b.stop("SCB CPACR enables the FPU: its lazy stacking is not modelled (the image is soft-float)");
    b.cpacr_ = value;
  } else return false;
  return true;
}

void Board::systick_advance() {
  const uint64_t now = cycles();
  uint64_t elapsed = now - syst_base_cycles_;
  syst_base_cycles_ = now;
  if (!(syst_csr_ & 1u)) return;
  // The counter decrements each HCLK; from 0 it reloads RVR at the next; 1 -> 0 sets COUNTFLAG and pends
  // SysTick with TICKINT (B3.3.1). A period is RVR + 1 clocks.
  while (elapsed > 0) {
    if (syst_cvr_ == 0) {
      syst_cvr_ = syst_rvr_;
      --elapsed;
      if (syst_rvr_ == 0) break;
      const uint64_t period = syst_rvr_ + 1ull;
      if (elapsed > 2 * period) {
        const uint64_t k = (elapsed - period) / period;
        elapsed -= k * period;
        syst_countflag_ = true;
        if (syst_csr_ & 2u) pend(kSysTick);
      }
      continue;
    }
    const uint64_t d = std::min<uint64_t>(syst_cvr_, elapsed);
    syst_cvr_ -= static_cast<uint32_t>(d);
    elapsed -= d;
    if (syst_cvr_ == 0) {
      syst_countflag_ = true;
      if (syst_csr_ & 2u) pend(kSysTick);
    }
  }
}

uint64_t Board::systick_next() const {
  if (!(syst_csr_ & 1u) || !(syst_csr_ & 2u) || syst_rvr_ == 0) return UINT64_MAX;
  return syst_base_cycles_ + (syst_cvr_ == 0 ? syst_rvr_ + 1ull : syst_cvr_);
}

std::string Board::load(const std::vector<uint8_t>& image_flash) {
  std::memcpy(flash_mem_.data(), image_flash.data(), std::min<size_t>(image_flash.size(), kFlashSize));
  return {};
}

std::string Board::init() {
  if (uc_open(UC_ARCH_ARM, static_cast<uc_mode>(UC_MODE_THUMB | UC_MODE_MCLASS), &uc_) != UC_ERR_OK) return "cannot open the Unicorn engine";
  if (uc_ctl_set_cpu_model(uc_, UC_CPU_ARM_CORTEX_M4) != UC_ERR_OK) return "the Unicorn engine has no Cortex-M4";
  // 32 MB of translated code (the image is under 128 KB), not the engine's default 1 GB: the board must run
  // in the 512 MB user-mode Linux guest of the CAN tests.
  if (uc_ctl_set_tcg_buffer_size(uc_, 32u * 1024u * 1024u) != UC_ERR_OK) return "cannot size the engine's code buffer";
  // Flash: code pages as host memory (read, execute), aliased at 0 (boot from main flash: RM0440 §2.6); the
  // two data pages at its end through the FLASH model.
  const uint32_t code = kDataPages - kFlashBase;
  uc_mem_map_ptr(uc_, kFlashBase, code, UC_PROT_READ | UC_PROT_EXEC, flash_mem_.data());
  uc_mem_map_ptr(uc_, 0, code, UC_PROT_READ | UC_PROT_EXEC, flash_mem_.data());
  uc_mem_map_ptr(uc_, kSramBase, kSramSize, UC_PROT_ALL, sram_.data());
  flash_data_ = std::make_unique<FlashData>(&flash_, kDataPages, this);
  for (uint32_t a : {kDataPages, kDataPages - kFlashBase}) {
    auto page = std::make_unique<MmioPage>(MmioPage{this, a});
    (void)page;
  }
  uc_mmio_map(uc_, kDataPages, 0x1000, &Board::data_read, this, &Board::data_write, this);
  // CCM SRAM at 0x10000000 shares the bytes seen at 0x20005800 (RM0440 §2.4.3); 12 KB window, 10 KB used.
  uc_mmio_map(uc_, kCcmBase, 0x3000, &Board::ccm_read, this, &Board::ccm_write, this);

  models_ = {&scs_, &rcc_, &pwr_, &flash_, &iwdg_, &gpioa_, &gpiob_, &gpioc_, &fdcan_, &sramcan_};
  rcc_.flash = &flash_;
  rcc_.pwr = &pwr_;
  gates_ = {{&gpioa_, 0x4C, 0}, {&gpiob_, 0x4C, 1}, {&gpioc_, 0x4C, 2}, {&fdcan_, 0x58, 25}, {&sramcan_, 0x58, 25}, {&pwr_, 0x58, 28}};
  for (auto& m : extra_) models_.push_back(m.get());
  for (Peripheral* m : models_) {
    m->attach(this);
    for (uint32_t a = m->base() & ~0xFFFu; a < m->base() + m->size(); a += 0x1000u) {
      if (mapped_pages_.count(a)) continue;
      pages_.push_back(std::make_unique<MmioPage>(MmioPage{this, a}));
      if (uc_mmio_map(uc_, a, 0x1000, &Board::mmio_read, pages_.back().get(), &Board::mmio_write, pages_.back().get()) != UC_ERR_OK) {
        return "cannot map the page of " + m->name();
      }
      mapped_pages_.insert(a);
    }
  }
  if (opt_.profile) {
    // The 1 kHz step (the board's tick and the core's step in it) and the policy's kernels, timed by symbol.
    profiler_ = std::make_unique<Profiler>();
    const std::string e = profiler_->load(opt_.elf, {"pour_board_loop_tick", "pour_control_step", "pour_policy_decide",
                                                     "pour_policy_fill_probs", "pour_policy_softmax_q15"});
    if (!e.empty()) return e;
  }
  uc_hook h;
  uc_hook_add(uc_, &h, UC_HOOK_BLOCK, reinterpret_cast<void*>(&Board::hook_block), this, 1, 0);
  uc_hook_add(uc_, &h, UC_HOOK_INTR, reinterpret_cast<void*>(&Board::hook_intr), this, 1, 0);
  uc_hook_add(uc_, &h, UC_HOOK_MEM_UNMAPPED, reinterpret_cast<void*>(&Board::hook_unmapped), this, 1, 0);
  uc_hook_add(uc_, &h, UC_HOOK_MEM_WRITE_PROT, reinterpret_cast<void*>(&Board::hook_unmapped), this, 1, 0);
  // The board's parts on the pins (docs/bringup.md, pour/board_facts.h): PB8 e-stop with a 10 kOhm pull-up,
  // a normally-closed contact to ground (closed: low); PB3 brake and PA15 enable with external pull-downs.
  gpiob_.external[8] = opt_.estop_open ? 1 : 0;
  gpiob_.external[3] = 0;
  gpioa_.external[15] = 0;
  if (!opt_.interface.empty()) {
    std::string e = open_can();
    if (!e.empty()) return e;
  }
  flash_.ecc_page = opt_.ecc_page;
  core_reset(true);
  return {};
}

uint64_t Board::data_read(uc_engine*, uint64_t off, unsigned size, void* user) {
  Board* b = static_cast<Board*>(user);
  uint32_t v = 0;
  b->flash_.data_read(static_cast<uint32_t>(kDataPages - kFlashBase + off), size, &v);
  if (b->flash_.nmi_pending) {
    b->flash_.nmi_pending = false;
    b->pend(kNmi);
    b->stop_soon_ = true;
  }
  return v;
}

void Board::data_write(uc_engine*, uint64_t off, unsigned size, uint64_t value, void* user) {
  Board* b = static_cast<Board*>(user);
  b->flash_.data_write(static_cast<uint32_t>(kDataPages - kFlashBase + off), size, static_cast<uint32_t>(value));
}

uint64_t Board::ccm_read(uc_engine*, uint64_t off, unsigned size, void* user) {
  Board* b = static_cast<Board*>(user);
  if (off + size > kCcmSize) {
    b->stop("read of 0x" + std::to_string(kCcmBase + off) + " beyond the 10 KB CCM SRAM");
    return 0;
  }
  uint32_t v = 0;
  std::memcpy(&v, b->sram_.data() + kCcmAlias + off, size);
  return v;
}

void Board::ccm_write(uc_engine*, uint64_t off, unsigned size, uint64_t value, void* user) {
  Board* b = static_cast<Board*>(user);
  if (off + size > kCcmSize) {
    b->stop("write beyond the 10 KB CCM SRAM");
    return;
  }
  uint32_t v = static_cast<uint32_t>(value);
  std::memcpy(b->sram_.data() + kCcmAlias + off, &v, size);
}

void Board::core_reset(bool power_on) {
  for (Peripheral* m : models_) m->reset();
  std::fill(std::begin(pending_), std::end(pending_), false);
  std::fill(std::begin(iser_), std::end(iser_), 0u);
  std::fill(std::begin(ipr_), std::end(ipr_), 0u);
  std::fill(std::begin(shpr_), std::end(shpr_), 0u);
  active_.clear();
  vtor_ = 0;
  prigroup_ = 0;
  syst_csr_ = syst_rvr_ = syst_cvr_ = 0;
  syst_countflag_ = false;
  syst_base_cycles_ = cycles();
  set_hclk(16000000u);
  uint32_t sp = 0, pc = 0;
  std::memcpy(&sp, flash_mem_.data(), 4);
  std::memcpy(&pc, flash_mem_.data() + 4, 4);
  uint32_t zero = 0, xpsr = 0x01000000u;
  for (int r = UC_ARM_REG_R0; r <= UC_ARM_REG_R12; ++r) uc_reg_write(uc_, r, &zero);
  uc_reg_write(uc_, UC_ARM_REG_PRIMASK, &zero);
  uc_reg_write(uc_, UC_ARM_REG_BASEPRI, &zero);
  uc_reg_write(uc_, UC_ARM_REG_CONTROL, &zero);
  uc_reg_write(uc_, UC_ARM_REG_XPSR, &xpsr);
  uc_reg_write(uc_, UC_ARM_REG_MSP, &sp);
  uc_reg_write(uc_, UC_ARM_REG_SP, &sp);
  uint32_t lr = 0xFFFFFFFFu;
  uc_reg_write(uc_, UC_ARM_REG_LR, &lr);
  pc_ = pc & ~1u;
  (void)power_on;
  if (profiler_) profiler_->reset();
}

void Board::take_exception(int exc) {
  uint32_t r[8];
  const int regs[8] = {UC_ARM_REG_R0, UC_ARM_REG_R1, UC_ARM_REG_R2, UC_ARM_REG_R3, UC_ARM_REG_R12, UC_ARM_REG_LR, UC_ARM_REG_PC, UC_ARM_REG_XPSR};
  for (int i = 0; i < 8; ++i) uc_reg_read(uc_, regs[i], &r[i]);
  uint32_t control = 0;
  uc_reg_read(uc_, UC_ARM_REG_CONTROL, &control);
  if (control & 2u) {
    stop("exception entry from the process stack (CONTROL.SPSEL): not modelled");
    return;
  }
  uint32_t sp = 0;
  uc_reg_read(uc_, UC_ARM_REG_SP, &sp);
  r[6] = pc_;
  // B1.5.6: eight words; with CCR.STKALIGN the frame is 8-byte aligned and xPSR bit 9 records the pad.
  const bool pad = (sp & 4u) != 0u;
  sp = (sp - (pad ? 4u : 0u)) - 32u;
  r[7] = (r[7] & ~(1u << 9)) | (pad ? 1u << 9 : 0u);
  if (sp < kSramBase || sp + 32u > kSramBase + kSramSize) {
    stop("exception entry: the stack frame at 0x" + std::to_string(sp) + " is outside SRAM (a stack overflow)");
    return;
  }
  uc_mem_write(uc_, sp, r, sizeof r);
  uc_reg_write(uc_, UC_ARM_REG_SP, &sp);
  const uint32_t exc_return = active_.empty() ? 0xFFFFFFF9u : 0xFFFFFFF1u;
  uc_reg_write(uc_, UC_ARM_REG_LR, &exc_return);
  uint32_t xpsr = 0x01000000u | static_cast<uint32_t>(exc);
  uc_reg_write(uc_, UC_ARM_REG_XPSR, &xpsr);
  uint32_t vector = 0;
  uc_mem_read(uc_, vtor_ + 4u * static_cast<uint32_t>(exc), &vector, 4);
  if (!(vector & 1u)) {
    stop("vector " + std::to_string(exc) + " is not a Thumb address");
    return;
  }
  pending_[exc] = false;
  active_.push_back(exc);
  if (trace_ && exc < 15) {
    std::fprintf(stderr, "trace: exception %d from pc 0x%08x at %.3f ms\n", exc, r[6], static_cast<double>(now_ps()) / 1e9);
  }
  pc_ = vector & ~1u;
  insns_ += 12;  // entry: 12 cycles (Cortex-M4 TRM §5.5.1), counted as instructions at CPI 1
  if (profiler_) profiler_->exception_entry(exc, pc_, 12);
  ++exceptions_taken_;
}

void Board::exception_return(uint32_t exc_return) {
  if (active_.empty()) {
    stop("exception return with no active exception");
    return;
  }
  if (exc_return != 0xFFFFFFF1u && exc_return != 0xFFFFFFF9u) {
    stop("EXC_RETURN 0x" + std::to_string(exc_return) + ": only the main stack without FPU frames is modelled");
    return;
  }
  uint32_t sp = 0, r[8];
  uc_reg_read(uc_, UC_ARM_REG_SP, &sp);
  uc_mem_read(uc_, sp, r, sizeof r);
  sp += 32u + ((r[7] >> 9) & 1u ? 4u : 0u);
  const int regs[6] = {UC_ARM_REG_R0, UC_ARM_REG_R1, UC_ARM_REG_R2, UC_ARM_REG_R3, UC_ARM_REG_R12, UC_ARM_REG_LR};
  for (int i = 0; i < 6; ++i) uc_reg_write(uc_, regs[i], &r[i]);
  uc_reg_write(uc_, UC_ARM_REG_SP, &sp);
  uint32_t xpsr = r[7] & ~(1u << 9);
  uc_reg_write(uc_, UC_ARM_REG_XPSR, &xpsr);
  const int done = active_.back();
  active_.pop_back();
  if (done >= 16 && irq_level_[done - 16]) pend(done);  // a level still high pends again
  pc_ = r[6] & ~1u;
  insns_ += 10;  // return: 10 cycles (Cortex-M4 TRM §5.5.1)
  if (profiler_) profiler_->exception_return(10);
}

std::string Board::open_can() {
  can_fd_ = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (can_fd_ < 0) return "cannot open a CAN socket: " + std::string(std::strerror(errno));
  ifreq ifr{};
  std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", opt_.interface.c_str());
  if (ioctl(can_fd_, SIOCGIFINDEX, &ifr) < 0) return "no CAN interface " + opt_.interface;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (bind(can_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) return "cannot bind " + opt_.interface;
  fcntl(can_fd_, F_SETFL, O_NONBLOCK);
  return {};
}

void Board::to_bus(const CanFrame& f) {
  if (can_fd_ < 0) return;
  can_frame cf{};
  cf.can_id = f.id;
  cf.can_dlc = f.dlc;
  std::memcpy(cf.data, f.data, 8);
  (void)!write(can_fd_, &cf, sizeof cf);
}

void Board::bridge() {
  while (!fdcan_.transmitted.empty()) {
    const CanFrame f = fdcan_.transmitted.front();
    fdcan_.transmitted.pop_front();
    ++frames_tx_;
    if (on_tx) on_tx(f);
    if ((f.id & 0x1Fu) == 1u && first_heartbeat_ps_ == UINT64_MAX) first_heartbeat_ps_ = now_ps();
    if (opt_.print_can) {
      std::printf("%.3f ms tx %03x [%u]", static_cast<double>(now_ps()) / 1e9, f.id, f.dlc);
      for (unsigned i = 0; i < f.dlc && i < 8; ++i) std::printf(" %02x", f.data[i]);
      std::printf("\n");
    }
    if (can_fd_ >= 0) {
      can_frame cf{};
      cf.can_id = f.id;
      cf.can_dlc = f.dlc;
      std::memcpy(cf.data, f.data, 8);
      (void)!write(can_fd_, &cf, sizeof cf);
    }
  }
  if (can_fd_ >= 0) {
    can_frame cf;
    while (read(can_fd_, &cf, sizeof cf) == static_cast<ssize_t>(sizeof cf)) {
      if (cf.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) continue;
      CanFrame f{cf.can_id & 0x7FFu, cf.can_dlc, {}};
      std::memcpy(f.data, cf.data, 8);
      fdcan_.receive(f);
    }
  }
}

int Board::run() {
  const auto wall0 = std::chrono::steady_clock::now();
  trace_ = std::getenv("POUR_VB_TRACE") != nullptr;
  const uint64_t end_ps = static_cast<uint64_t>(opt_.seconds * 1e12);
  const uint64_t slice_max = 170000;  // at most 1 ms of the core at 170 MHz between bridge polls
  while (stopped_.empty()) {
    if (!reset_cause_.empty()) {
      std::fprintf(stderr, "virtual board: reset at %.3f ms: %s\n", static_cast<double>(now_ps()) / 1e9, reset_cause_.c_str());
      ++resets_;
      const bool iwdg = reset_cause_.rfind("IWDG", 0) == 0;
      rcc_.note_reset(iwdg ? (1u << 29) | (1u << 26) : (1u << 28) | (1u << 26));  // IWDGRSTF or SFTRSTF, and PINRSTF
      reset_cause_.clear();
      core_reset(false);
      if (opt_.stop_on_reset) break;
    }
    if (now_ps() >= end_ps || finish_) break;
    if (opt_.until_heartbeat && first_heartbeat_ps_ != UINT64_MAX) break;
    // Pending exceptions, highest priority first, while they preempt.
    for (int guard = 0; guard < 4; ++guard) {
      const int e = best_pending();
      if (e < 0 || priority(e) >= execution_priority()) break;
      take_exception(e);
      if (!stopped_.empty()) break;
    }
    if (!stopped_.empty()) break;
    // The next event: SysTick, every model's, the end of the run.
    uint64_t next = std::min(systick_next(), cycles() + slice_max);
    for (Peripheral* m : models_) next = std::min(next, m->next_event());
    next = std::min(next, cycles() + cycles_until_ps(end_ps));
    if (next <= cycles()) next = cycles() + 1;
    slice_end_ = (next * 1000u + opt_.cpi_milli - 1u) / opt_.cpi_milli;
    idle_ = false;
    stall_ = false;
    stop_soon_ = false;
    intno_ = -1;
    const uint64_t before = insns_;
    if (trace_ && (++iterations_ % 100000u) == 0u) {
      std::fprintf(stderr, "trace: pc 0x%08x insns %llu end %llu t %.3f ms active %zu\n", pc_, (unsigned long long)insns_,
                   (unsigned long long)slice_end_, static_cast<double>(now_ps()) / 1e9, active_.size());
    }
    uc_err err = uc_emu_start(uc_, pc_ | 1u, 0xFFFFFFFFu, 0, 0);
    uint32_t pc = 0;
    uc_reg_read(uc_, UC_ARM_REG_PC, &pc);
    pc_ = pc;
    if (err != UC_ERR_OK && stopped_.empty()) {
      stop(std::string("the core stopped: ") + uc_strerror(err));
      break;
    }
    if (intno_ == 8) {  // EXCP_EXCEPTION_EXIT: a branch to EXC_RETURN in handler mode
      exception_return(pc | 1u);
    } else if (intno_ >= 0 && stopped_.empty()) {
      // An undefined instruction, a breakpoint, an SVC: HardFault (UsageFault escalates, SHCSR leaves it off).
      if (intno_ == 2) pend(11);
      else pend(kHardFault);
      if (std::find(active_.begin(), active_.end(), kHardFault) != active_.end()) {
        stop("lockup: a fault inside the HardFault handler (intno " + std::to_string(intno_) + ")");
      }
    }
    uint16_t last = 0;
    if (pc >= 2 && uc_mem_read(uc_, pc - 2, &last, 2) == UC_ERR_OK && last == 0xBF30u && insns_ == before + 0) {}
    const bool wfi = intno_ < 0 && !idle_ && insns_ < slice_end_ && last == 0xBF30u;
    if (stall_ && flash_.stall_until_ps > now_ps()) {
      // The erase holds the core: no fetch until it ends (the models run on; the IWDG may expire meanwhile).
      const uint64_t target = std::min(flash_.stall_until_ps, std::max(now_ps(), iwdg_.expiry_ps()));
      insns_ = std::max(insns_, ((cycles() + cycles_until_ps(target)) * 1000u + opt_.cpi_milli - 1u) / opt_.cpi_milli);
      if (iwdg_.running() && iwdg_.expiry_ps() < flash_.stall_until_ps) {
        std::fprintf(stderr, "virtual board: IWDG timeout %.3f ms is shorter than the flash page erase %.3f ms\n",
                     static_cast<double>(iwdg_.timeout_ps()) / 1e9, static_cast<double>(flash_.erase_ps) / 1e9);
      }
    } else if (idle_ || (wfi && best_pending() < 0)) {
      insns_ = std::max(insns_, slice_end_);  // nothing runs until the next event
      idle_cycles_ += 1;
    }
    if (opt_.stall_core_at_ms >= 0 && now_ps() >= static_cast<uint64_t>(opt_.stall_core_at_ms * 1e9) && !stalled_once_) {
      // Injection: the core stops fetching (a hung bus) for stall_core_ms; the IWDG is not refreshed.
      // The watchdog's reset, if it comes first, ends the stall (the models run on to it).
      stalled_once_ = true;
      const uint64_t at = now_ps();
      uint64_t until = at + static_cast<uint64_t>(opt_.stall_core_ms * 1e9);
      if (iwdg_.running()) until = std::min(until, std::max(at, iwdg_.expiry_ps()));
      insns_ += (cycles_until_ps(until) * 1000u + opt_.cpi_milli - 1u) / opt_.cpi_milli;
      std::fprintf(stderr, "virtual board: core stalled %.1f ms at %.3f ms (injected)\n", opt_.stall_core_ms, static_cast<double>(at) / 1e9);
    }
    systick_advance();
    for (Peripheral* m : models_) m->advance();
    bridge();
    if (opt_.realtime) {
      const double emu = static_cast<double>(now_ps()) / 1e12;
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
      if (emu > wall + 0.002) std::this_thread::sleep_for(std::chrono::duration<double>(emu - wall));
    }
  }
  wall_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (profiler_) profiler_->report(stdout, opt_.cpi_milli, hclk_, static_cast<double>(now_ps()) / 1e12);
  if (!stopped_.empty()) {
    std::fprintf(stderr, "virtual board: stopped: %s\n", stopped_.c_str());
    return 1;
  }
  return 0;
}

}  // namespace vb
