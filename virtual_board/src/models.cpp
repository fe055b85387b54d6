// SPDX-License-Identifier: MIT
#include "models.hpp"

#include <cstring>

extern "C" {
#include "pour/board_facts.h"
}

namespace vb {

const std::vector<SvdPeriph>& svd_periphs() {
  static const std::vector<SvdPeriph> p = {
#define VB_PERIPH(name, base) {name, base},
#define VB_REG(periph, name, offset, width, reset)
#include "svd_map.inc"
#undef VB_PERIPH
#undef VB_REG
  };
  return p;
}

const std::vector<SvdReg>& svd_regs() {
  static const std::vector<SvdReg> r = {
#define VB_PERIPH(name, base)
#define VB_REG(periph, name, offset, width, reset) {periph, name, offset, width, reset},
#include "svd_map.inc"
#undef VB_PERIPH
#undef VB_REG
  };
  return r;
}

std::string svd_name_at(uint32_t addr) {
  std::string best;
  uint32_t best_base = 0;
  for (const auto& p : svd_periphs()) {
    if (addr >= p.base && addr - p.base < 0x400u && (best.empty() || p.base > best_base)) {
      best = p.name;
      best_base = p.base;
    }
  }
  return best;
}

uint32_t svd_base(const std::string& svd_name) {
  for (const auto& p : svd_periphs()) {
    if (svd_name == p.name) return p.base;
  }
  return 0;
}

SvdRegisters::SvdRegisters(const std::string& svd_name, const std::string& name, uint32_t size)
    : Peripheral(name, svd_base(svd_name), size) {
  for (const auto& r : svd_regs()) {
    if (svd_name == r.periph) resets_[r.offset] = r.reset;
  }
  reset();
}

void SvdRegisters::reset() { regs_ = resets_; }

bool SvdRegisters::read(uint32_t offset, unsigned width, uint32_t* value) {
  const uint32_t word = offset & ~3u;
  auto it = regs_.find(word);
  if (it == regs_.end()) return false;
  const uint32_t v = on_read(word, it->second);
  const unsigned shift = 8u * (offset & 3u);
  *value = width == 4u ? v : (v >> shift) & ((1u << (8u * width)) - 1u);
  return true;
}

bool SvdRegisters::write(uint32_t offset, unsigned width, uint32_t value) {
  const uint32_t word = offset & ~3u;
  auto it = regs_.find(word);
  if (it == regs_.end()) return false;
  const uint32_t old = it->second;
  uint32_t v = value;
  if (width != 4u) {
    const unsigned shift = 8u * (offset & 3u);
    const uint32_t mask = ((1u << (8u * width)) - 1u) << shift;
    v = (old & ~mask) | ((value << shift) & mask);
  }
  on_write(word, old, &v);
  regs_[word] = v;
  return true;
}

// ---------------------------------------------------------------------------------------------------- RCC
// RM0440 §7.4. Ready flags follow their enables after the datasheet's start-up times: HSE (an 8 MHz
// crystal, board_facts.h HSE_HZ) tSU(HSE) 2 ms typical; the PLL tLOCK 40 us maximum. HSI16 is on from reset.
namespace {
constexpr uint64_t kHseStartPs = 2000000000ull;
constexpr uint64_t kPllLockPs = 40000000ull;
constexpr uint32_t kCR = 0x00, kCFGR = 0x08, kPLLCFGR = 0x0C, kCSR = 0x94;
}  // namespace

void Rcc::reset() {
  SvdRegisters::reset();
  // RM0440 RCC_CR reset value 0x0000 0500 (HSION, HSIRDY); the crate's SVD gives 0x63, whose bits are
  // reserved in RM0440: the manual's is taken.
  reg(kCR) = 0x00000500u;
  hse_on_ps_ = pll_on_ps_ = UINT64_MAX;
  sws_ = 1u;
}

bool Rcc::ready(unsigned which) const {
  const uint64_t now = t_->now_ps();
  if (which == 0) return hse_on_ps_ != UINT64_MAX && now >= hse_on_ps_ + kHseStartPs;
  return pll_on_ps_ != UINT64_MAX && now >= pll_on_ps_ + kPllLockPs;
}

uint32_t Rcc::on_read(uint32_t offset, uint32_t stored) {
  if (offset == kCR) {
    uint32_t v = stored & ~((1u << 17) | (1u << 25));
    if (ready(0)) v |= 1u << 17;
    if (ready(1)) v |= 1u << 25;
    return v;
  }
  if (offset == kCFGR) return (stored & ~0xCu) | (sws_ << 2);
  if (offset == kCSR) return (stored & ~0xFE000000u) | csr_flags_ | 0x2u /* LSIRDY: LSI runs with the IWDG */;
  return stored;
}

void Rcc::on_write(uint32_t offset, uint32_t old, uint32_t* value) {
  if (offset == kCR) {
    *value |= 0x400u;  // HSIRDY with HSION (never switched off here)
    if ((*value & (1u << 16)) && !(old & (1u << 16))) hse_on_ps_ = t_->now_ps();
    if (!(*value & (1u << 16))) hse_on_ps_ = UINT64_MAX;
    if ((*value & (1u << 24)) && !(old & (1u << 24))) pll_on_ps_ = t_->now_ps();
    if (!(*value & (1u << 24))) pll_on_ps_ = UINT64_MAX;
    if ((old & (1u << 24)) && (old & (1u << 25)) && sws_ == 3u && !(*value & (1u << 24))) {
      link_->stop("RCC: PLLON cleared while the PLL clocks the system (RM0440 §7.4.1)");
    }
  } else if (offset == kPLLCFGR) {
    if (reg(kCR) & (1u << 24)) link_->stop("RCC: PLLCFGR written with the PLL on (RM0440 §7.4.4: only with PLLON = 0)");
  } else if (offset == kCFGR) {
    const uint32_t sw = *value & 3u;
    // The switch happens once the source is ready (RM0440 §7.2.7); else SWS keeps the old source.
    if (sw == 1u || (sw == 2u && ready(0)) || (sw == 3u && ready(1))) sws_ = sw;
  } else if (offset == kCSR) {
    if (*value & (1u << 23)) csr_flags_ = 0;  // RMVF
  }
  (void)old;
}

uint32_t Rcc::hclk_hz() {
  uint64_t sys = 16000000u;
  if (sws_ == 2u) sys = static_cast<uint64_t>(POUR_BOARD_HSE_HZ);
  if (sws_ == 3u) {
    const uint32_t p = reg(kPLLCFGR);
    const uint64_t in = (p & 3u) == 3u ? static_cast<uint64_t>(POUR_BOARD_HSE_HZ) : 16000000u;
    const uint32_t m = ((p >> 4) & 0xFu) + 1u, n = (p >> 8) & 0x7Fu, r = 2u * (((p >> 25) & 3u) + 1u);
    sys = in / m * n / r;
  }
  const uint32_t hpre = (reg(kCFGR) >> 4) & 0xFu;
  static const unsigned shifts[8] = {1, 2, 3, 4, 6, 7, 8, 9};
  const uint32_t hclk = static_cast<uint32_t>(hpre < 8u ? sys : sys >> shifts[hpre - 8u]);
  // RM0440 §3.3.3 table 9: HCLK per wait state, range 1 boost (34 MHz a state) or normal (30 MHz).
  if (flash != nullptr && pwr != nullptr) {
    const uint32_t per_ws = pwr->boost() ? 34000000u : 30000000u;
    const uint32_t ws = flash->latency();
    if (hclk > per_ws * (ws + 1u)) {
      link_->stop("FLASH: ACR LATENCY " + std::to_string(ws) + " too few wait states for HCLK " + std::to_string(hclk) +
                  " Hz (RM0440 table 9)");
    }
    if (hclk > 150000000u && !pwr->boost()) link_->stop("PWR: HCLK above 150 MHz without range 1 boost (RM0440 §6.1.5)");
  }
  return hclk;
}

void Rcc::advance() {}

uint64_t Rcc::next_event() const { return UINT64_MAX; }

// ---------------------------------------------------------------------------------------------------- IWDG
// RM0440 §41: KR 0xCCCC starts, 0x5555 unlocks PR/RLR/WINR, 0xAAAA reloads; the counter runs at LSI / (4 <<
// PR) from RLR to 0, then resets the chip. PVU/RVU/WVU are busy for 5 LSI periods after a write (§41.3.4).
void Iwdg::reset() {
  SvdRegisters::reset();
  running_ = unlocked_ = false;
  reload_ps_ = busy_until_ps_ = 0;
  domain_pr_ = 0;
  domain_rl_ = 0xFFFu;
  loaded_ps_ = 0;
}

void Iwdg::settle() {
  if (t_->now_ps() < busy_until_ps_) return;
  domain_pr_ = regs_.at(0x04) & 7u;
  domain_rl_ = regs_.at(0x08) & 0xFFFu;
}

void Iwdg::reload(bool start) {
  settle();
  reload_ps_ = t_->now_ps();
  // Started by 0xCCCC, the counter counts down from its reset value 0xFFF (RM0440 §41.3.2); 0xAAAA loads RLR.
  const uint32_t count = start ? 0xFFFu : domain_rl_;
  loaded_ps_ = (uint64_t)(count + 1u) * (4u << (domain_pr_ > 6u ? 6u : domain_pr_)) * 1000000000000ull / lsi_hz;
}

uint32_t Iwdg::on_read(uint32_t offset, uint32_t stored) {
  if (offset == 0x0C) return t_->now_ps() < busy_until_ps_ ? 0x7u & stored : 0u;
  if (offset == 0x00) return 0u;
  return stored;
}

void Iwdg::on_write(uint32_t offset, uint32_t old, uint32_t* value) {
  const uint64_t now = t_->now_ps();
  if (offset == 0x00) {
    const uint32_t key = *value & 0xFFFFu;
    if (key == 0xCCCCu) {
      if (!running_) reload(true);
      running_ = true;
    } else if (key == 0x5555u) {
      unlocked_ = true;
    } else if (key == 0xAAAAu) {
      reload(false);
      unlocked_ = false;
    } else {
      unlocked_ = false;
    }
    *value = 0;
    return;
  }
  if (offset == 0x04 || offset == 0x08 || offset == 0x10) {
    if (!unlocked_) {
      *value = old;  // write-protected (RM0440 §41.3.6): ignored by the chip
      return;
    }
    settle();  // what an earlier write had settled stays in the domain until this one does
    busy_until_ps_ = now + 5ull * 1000000000000ull / lsi_hz;
    regs_[0x0C] |= offset == 0x04 ? 1u : offset == 0x08 ? 2u : 4u;
  }
}

void Iwdg::advance() {
  if (running_ && t_->now_ps() >= expiry_ps()) {
    running_ = false;
    link_->request_reset("IWDG: no refresh within " + std::to_string(timeout_ps() / 1000000000ull) + " ms");
  }
}

uint64_t Iwdg::next_event() const {
  return running_ ? link_->cycles() + t_->cycles_until_ps(expiry_ps()) : UINT64_MAX;
}

// ---------------------------------------------------------------------------------------------------- FLASH
namespace {
constexpr uint32_t kKEYR = 0x08, kSR = 0x10, kFCR = 0x14, kECCR = 0x18, kOPTR = 0x20;
constexpr uint32_t kBSY = 1u << 16, kLOCK = 1u << 31;
constexpr uint32_t kSrErrors = 0x3FAu | (1u << 14) | (1u << 15);  // OPERR .. FASTERR, RDERR, OPTVERR
// The option bytes a programmed board carries: the factory value of FLASH_OPTR (RM0440 §5.4.1, 0xFFEF F8AA)
// with nSWBOOT0 = 0 and nBOOT0 = 1 (boot from main flash whatever PB8 reads), as scripts/flash.sh's
// bring-up asks the option bytes to be set (docs/bringup.md).
constexpr uint32_t kOptr = 0xFFEFF8AAu & ~(1u << 26);
}  // namespace

void Flash::reset() {
  SvdRegisters::reset();
  reg(kOPTR) = kOptr;
  key_state_ = 0;
  busy_until_ps_ = stall_until_ps = 0;
  pending_low_ = false;
}

uint32_t Flash::on_read(uint32_t offset, uint32_t stored) {
  if (offset == kSR) return t_->now_ps() < busy_until_ps_ ? stored | kBSY : stored & ~kBSY;
  return stored;
}

void Flash::on_write(uint32_t offset, uint32_t old, uint32_t* value) {
  if (offset == kKEYR) {
    if (key_state_ == 0 && *value == 0x45670123u) {
      key_state_ = 1;
    } else if (key_state_ == 1 && *value == 0xCDEF89ABu) {
      key_state_ = 0;
      reg(kFCR) &= ~kLOCK;
    } else {
      key_state_ = 2;  // a wrong sequence locks FLASH_CR until the next reset (RM0440 §3.3.6)
    }
    *value = 0;
    return;
  }
  if (offset == kSR) {
    *value = old & ~(*value & (kSrErrors | 1u));  // write 1 to clear
    return;
  }
  if (offset == kECCR) {
    *value = (old & ~(*value & 0xC0000000u)) | (*value & 0x01000000u);  // ECCC, ECCD rc_w1; ECCIE
    return;
  }
  if (offset == kFCR) {
    if (old & kLOCK) {
      *value = old;  // locked: ignored
      return;
    }
    if ((*value & (1u << 16)) && (*value & 2u)) {  // PER + STRT: a page erase
      if (t_->now_ps() < busy_until_ps_) {
        link_->stop("FLASH: STRT while BSY (RM0440 §3.3.7)");
        return;
      }
      const uint32_t page = (*value >> 3) & 0x7Fu;
      if (page * 2048u + 2048u > size_) {
        link_->stop("FLASH: page " + std::to_string(page) + " beyond the 128 KB");
        return;
      }
      std::memset(mem_ + page * 2048u, 0xFF, 2048u);
      if (ecc_page == static_cast<int>(page)) ecc_page = -1;
      busy_until_ps_ = t_->now_ps() + erase_ps;
      stall_until_ps = busy_until_ps_;  // single bank: the next fetch waits for the erase
      reg(kSR) |= 1u;                   // EOP (reported whether or not EOPIE)
      *value &= ~(1u << 16);
    }
  }
}

bool Flash::data_read(uint32_t offset, unsigned width, uint32_t* value) {
  if (ecc_page >= 0 && offset / 2048u == static_cast<uint32_t>(ecc_page)) {
    // RM0440 §3.3.5: a double error on a read sets ECCD with the address and raises the NMI.
    reg(kECCR) = (reg(kECCR) & 0x01000000u) | (1u << 31) | ((offset >> 3) << 3 & 0x7FFFFu);
    nmi_pending = true;
    *value = 0xDEADBEEFu & ((width == 4u) ? 0xFFFFFFFFu : (1u << (8u * width)) - 1u);
    return true;
  }
  uint32_t v = 0;
  std::memcpy(&v, mem_ + offset, width);
  *value = v;
  return true;
}

bool Flash::data_write(uint32_t offset, unsigned width, uint32_t value) {
  // RM0440 §3.3.7: with PG set, two 32-bit writes to a double word's address program it; anything else
  // (a byte or half-word write, a second half at another address, PG clear) is an error.
  const uint32_t cr = reg(kFCR);
  if (!(cr & 1u) || (cr & kLOCK)) {
    reg(kSR) |= 1u << 7;  // PGSERR
    link_->stop("FLASH: write to 0x" + std::to_string(0x08000000u + offset) + " without PG (RM0440 §3.3.7)");
    return true;
  }
  if (width != 4u) {
    reg(kSR) |= 1u << 6;  // SIZERR
    return true;
  }
  if (!pending_low_) {
    if (offset & 7u) {
      reg(kSR) |= 1u << 5;  // PGAERR
      return true;
    }
    pending_low_ = true;
    low_word_ = value;
    low_offset_ = offset;
    return true;
  }
  pending_low_ = false;
  if (offset != low_offset_ + 4u) {
    reg(kSR) |= 1u << 5;
    return true;
  }
  uint32_t cur[2];
  std::memcpy(cur, mem_ + low_offset_, 8);
  if (cur[0] != 0xFFFFFFFFu || cur[1] != 0xFFFFFFFFu) {
    reg(kSR) |= 1u << 3;  // PROGERR: the double word was not erased
    return true;
  }
  std::memcpy(mem_ + low_offset_, &low_word_, 4);
  std::memcpy(mem_ + offset, &value, 4);
  busy_until_ps_ = t_->now_ps() + program_ps;
  reg(kSR) |= 1u;
  return true;
}

void Flash::advance() {}
uint64_t Flash::next_event() const { return UINT64_MAX; }

// ---------------------------------------------------------------------------------------------------- GPIO
// RM0440 §9.4: IDR reads the pin; a pin the chip drives (output, push-pull) reads its ODR; an input reads the
// external part, else the pull the PUPDR selects, else (floating) 0 in this model.
bool Gpio::driven_high(unsigned pin) { return is_output(pin) && (reg(0x14) >> pin & 1u); }

uint32_t Gpio::on_read(uint32_t offset, uint32_t stored) {
  if (offset != 0x10) return offset == 0x18 ? 0u : stored;
  uint32_t idr = 0;
  for (unsigned pin = 0; pin < 16; ++pin) {
    const uint32_t mode = (reg(0x00) >> (2u * pin)) & 3u;
    const uint32_t pull = (reg(0x0C) >> (2u * pin)) & 3u;
    int level = 0;
    if (mode == 1u || mode == 2u) {
      level = mode == 1u ? static_cast<int>(reg(0x14) >> pin & 1u) : 0;
      if (mode == 2u && external[pin] >= 0) level = external[pin];
    } else if (mode == 0u) {
      level = external[pin] >= 0 ? external[pin] : pull == 1u ? 1 : 0;
    }
    idr |= static_cast<uint32_t>(level) << pin;
  }
  return idr;
}

void Gpio::on_write(uint32_t offset, uint32_t old, uint32_t* value) {
  if (offset == 0x10) {
    *value = old;  // IDR is read-only
  } else if (offset == 0x18) {  // BSRR: set, then reset wins
    uint32_t odr = reg(0x14);
    odr |= *value & 0xFFFFu;
    odr &= ~(*value >> 16);
    reg(0x14) = odr;
    *value = 0;
  } else if (offset == 0x28) {  // BRR
    reg(0x14) &= ~(*value & 0xFFFFu);
    *value = 0;
  }
}

// ---------------------------------------------------------------------------------------------------- FDCAN
namespace {
constexpr uint32_t kCCCR = 0x18, kNBTP = 0x1C, kIR = 0x50, kRXGFC = 0x80, kRXF0S = 0x90, kRXF0A = 0x94,
                   kTXBC = 0xC0, kTXFQS = 0xC4, kTXBRP = 0xC8, kTXBAR = 0xCC, kTXBTO = 0xD4;
constexpr uint32_t kRamRf0 = 0xB0 / 4, kRamTx = 0x278 / 4, kElem = 18;
}  // namespace

void Fdcan::reset() {
  SvdRegisters::reset();
  rx_get_ = rx_fill_ = tx_get_ = tx_fill_ = tx_pending_ = 0;
  tx_done_ps_ = UINT64_MAX;
  transmitted.clear();
}

uint64_t Fdcan::bit_ps() const {
  const uint32_t n = regs_.at(kNBTP);
  const uint32_t brp = ((n >> 16) & 0x1FFu) + 1u, seg1 = ((n >> 8) & 0xFFu) + 1u, seg2 = (n & 0x7Fu) + 1u;
  // The kernel clock is PCLK1 (RCCIPR FDCANSEL = 2, as the port sets it): the HCLK here (APB /1).
  const uint64_t hz = link_->hclk_hz();
  return (uint64_t)brp * (1u + seg1 + seg2) * 1000000000000ull / hz;
}

uint32_t Fdcan::on_read(uint32_t offset, uint32_t stored) {
  if (offset == kRXF0S) {
    const uint32_t put = (rx_get_ + rx_fill_) % 3u;
    return (stored & (1u << 25)) | rx_fill_ | (rx_get_ << 8) | (put << 16) | (rx_fill_ == 3u ? 1u << 24 : 0u);
  }
  if (offset == kTXFQS) {
    const uint32_t used = tx_fill_;
    const uint32_t put = (tx_get_ + tx_fill_) % 3u;
    return (3u - used) | (tx_get_ << 8) | (put << 16) | (used == 3u ? 1u << 21 : 0u);
  }
  if (offset == kTXBRP) return tx_pending_;
  return stored;
}

void Fdcan::on_write(uint32_t offset, uint32_t old, uint32_t* value) {
  const bool init = regs_[kCCCR] & 1u, cce = regs_[kCCCR] & 2u;
  if (offset == kCCCR) {
    if (!init) *value = (old & ~3u) | (*value & 1u);  // CCE only while INIT (RM0440 §44.4.8)
    if (!(*value & 1u)) *value &= ~2u;                // leaving INIT clears CCE
    return;
  }
  if (offset == kIR) {
    *value = old & ~*value;  // write 1 to clear
    if (!(*value & 4u)) regs_[kRXF0S] &= ~(1u << 25);
    return;
  }
  const bool protected_reg = offset == kNBTP || offset == 0x0C || offset == kRXGFC || offset == 0x84 || offset == kTXBC ||
                             offset == 0x10 || offset == 0x14;
  if (protected_reg && !(init && cce)) {
    link_->stop("FDCAN1: protected register 0x" + std::to_string(offset) + " written without INIT and CCE (RM0440 §44.4)");
    return;
  }
  if (offset == kRXF0A) {
    const uint32_t idx = *value & 3u;
    if (rx_fill_ > 0 && idx < 3u) {
      const uint32_t n = (idx + 3u - rx_get_) % 3u + 1u;  // acknowledges up to and including idx
      rx_fill_ = n > rx_fill_ ? 0 : rx_fill_ - n;
      rx_get_ = (idx + 1u) % 3u;
    }
    return;
  }
  if (offset == kTXBAR) {
    if (init) return;
    const uint32_t put = (tx_get_ + tx_fill_) % 3u;
    if ((*value & 7u) != 0u && tx_fill_ < 3u && (*value & (1u << put))) {
      tx_fill_++;
      tx_pending_ |= 1u << put;
      if (tx_done_ps_ == UINT64_MAX) tx_done_ps_ = t_->now_ps() + 111u * bit_ps();  // a classic 8-byte frame
    }
    *value = 0;
  }
}

void Fdcan::advance() {
  while (tx_fill_ > 0 && t_->now_ps() >= tx_done_ps_) {
    const uint32_t* e = &ram[kRamTx + tx_get_ * kElem];
    CanFrame f{};
    f.id = (e[0] >> 18) & 0x7FFu;
    f.dlc = static_cast<uint8_t>((e[1] >> 16) & 0xFu);
    std::memcpy(f.data, &e[2], 8);
    transmitted.push_back(f);
    regs_[kTXBTO] |= 1u << tx_get_;
    tx_pending_ &= ~(1u << tx_get_);
    tx_get_ = (tx_get_ + 1u) % 3u;
    tx_fill_--;
    tx_done_ps_ = tx_fill_ > 0 ? tx_done_ps_ + 111u * bit_ps() : UINT64_MAX;
  }
}

uint64_t Fdcan::next_event() const {
  return tx_done_ps_ == UINT64_MAX ? UINT64_MAX : link_->cycles() + t_->cycles_until_ps(tx_done_ps_);
}

void Fdcan::receive(const CanFrame& f) {
  if (regs_[kCCCR] & 1u) return;  // in INIT: not on the bus
  // Standard filters (LSS of them at the RAM's start): classic filter (SFT 2) id/mask, SFEC 1 to FIFO 0.
  const uint32_t lss = (regs_[kRXGFC] >> 16) & 0x1Fu;
  bool accept = false;
  for (uint32_t i = 0; i < lss && i < 28u; ++i) {
    const uint32_t s = ram[i];
    const uint32_t sft = s >> 30, sfec = (s >> 27) & 7u, id1 = (s >> 16) & 0x7FFu, id2 = s & 0x7FFu;
    bool match = false;
    if (sft == 2u) match = (f.id & id2) == (id1 & id2);
    if (sft == 1u) match = f.id == id1 || f.id == id2;
    if (sft == 0u) match = f.id >= id1 && f.id <= id2;
    if (match && sfec == 1u) accept = true;
    if (match) break;
  }
  if (!accept && ((regs_[kRXGFC] >> 4) & 3u) == 0u) accept = true;  // ANFS 0: non-matching to FIFO 0
  if (!accept) return;
  if (rx_fill_ == 3u) {
    regs_[kIR] |= 1u << 2;  // RF0L
    regs_[kRXF0S] |= 1u << 25;
    if (!(regs_[kRXGFC] & (1u << 9))) return;  // blocking mode: the new one is lost
    rx_get_ = (rx_get_ + 1u) % 3u;              // overwrite: the oldest goes
    rx_fill_--;
  }
  const uint32_t put = (rx_get_ + rx_fill_) % 3u;
  uint32_t* e = &ram[kRamRf0 + put * kElem];
  e[0] = (f.id & 0x7FFu) << 18;
  e[1] = static_cast<uint32_t>(f.dlc) << 16;
  std::memcpy(&e[2], f.data, 8);
  rx_fill_++;
  regs_[kIR] |= 1u;  // RF0N
}

bool SramCan::read(uint32_t offset, unsigned width, uint32_t* value) {
  if (offset >= 0x350u) return false;
  uint32_t v = 0;
  std::memcpy(&v, reinterpret_cast<uint8_t*>(can_->ram) + offset, width);
  *value = v;
  return true;
}

bool SramCan::write(uint32_t offset, unsigned width, uint32_t value) {
  if (offset >= 0x350u) return false;
  std::memcpy(reinterpret_cast<uint8_t*>(can_->ram) + offset, &value, width);
  return true;
}

}  // namespace vb
