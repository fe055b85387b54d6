// SPDX-License-Identifier: MIT
// TIM4 in encoder mode (RM0440 29.3.22: SMS 1 / 2 count the edges of one input, 3 of both; CC1P / CC2P
// invert an input and with it the direction; the 16-bit counter wraps between 0 and ARR with UIF) and
// LPTIM1 counting its kernel clock through PRESC (RM0440 section 33: ENABLE, CNTSTRT, ARR / ARROK).
#include <cmath>
#include <string>

#include "access.hpp"
#include "analog.hpp"
#include "models.hpp"

namespace vb {

// ----------------------------------------------------------------------------------------------- TIM4
namespace {
enum : uint32_t {
  T_CR1 = 0x00, T_CR2 = 0x04, T_SMCR = 0x08, T_DIER = 0x0C, T_SR = 0x10, T_EGR = 0x14, T_CCMR1 = 0x18,
  T_CCMR2 = 0x1C, T_CCER = 0x20, T_CNT = 0x24, T_PSC = 0x28, T_ARR = 0x2C, T_CCR1 = 0x34, T_CCR4 = 0x40,
  T_ECR = 0x58, T_TISEL = 0x5C, T_AF1 = 0x60, T_AF2 = 0x64, T_DCR = 0x3DC, T_DMAR = 0x3E0
};
}  // namespace

void Tim4::reset() {
  // SVD (the crate's TIM3 block, which TIM4 shares): 0 everywhere but ARR 0xFFFFFFFF. The counter itself is
  // 16-bit (RM0440 29.1: TIM3 / TIM4 16-bit): it wraps at ARR's low half.
  cr1_ = cr2_ = smcr_ = dier_ = sr_ = ccmr1_ = ccmr2_ = ccer_ = cnt_ = psc_ = ecr_ = tisel_ = af1_ = af2_ = dcr_ = 0;
  arr_ = 0xFFFFFFFFu;
  for (auto& c : ccr_) c = 0;
  half_ = 0;
}

void Tim4::count(int64_t n) {
  const int64_t arr16 = static_cast<int64_t>(arr_ & 0xFFFFu);
  const int64_t top = arr16 + 1;
  int64_t c = static_cast<int64_t>(cnt_) + n;
  if (c > arr16 || c < 0) {
    sr_ |= 1u;  // UIF at each wrap (UDIS clear)
    c = ((c % top) + top) % top;
  }
  cnt_ = static_cast<uint32_t>(c);
  if (n != 0) cr1_ = (cr1_ & ~(1u << 4u)) | (n < 0 ? 1u << 4u : 0u);  // DIR follows the count
  if (link_ != nullptr) link_->set_irq(IRQ_TIM4, (sr_ & dier_ & 1u) != 0u);
}

uint32_t Tim4::merge_base(uint32_t off, uint32_t current) const {
  if (off == T_SR) return 0xFFFFFFFFu;
  if (off == T_EGR) return 0u;
  return current;
}

void Tim4::edges(int64_t x4) {
  if (!bit(cr1_, 0u) || x4 == 0) return;  // CEN
  const uint32_t sms = field(smcr_, 0u, 3u) | (field(smcr_, 16u, 1u) << 3u);
  // Both inputs mapped on their own pins (CC1S = CC2S = 01: TI1FP1, TI2FP2), as the encoder modes need.
  if (field(ccmr1_, 0u, 2u) != 1u || field(ccmr1_, 8u, 2u) != 1u) return;
  // One inverted input reverses the direction (RM0440 table "counting direction versus encoder signals").
  const bool rev = bit(ccer_, 1u) != bit(ccer_, 5u);
  const int64_t n = rev ? -x4 : x4;
  if (sms == 3u) {
    count(n);
  } else if (sms == 1u || sms == 2u) {
    half_ += n;  // edges of one input only: half of them
    const int64_t whole = half_ / 2;
    half_ -= whole * 2;
    count(whole);
  }
}

bool Tim4::read32(uint32_t off, uint32_t* v) {
  switch (off) {
    case T_CR1: *v = cr1_; return true;
    case T_CR2: *v = cr2_; return true;
    case T_SMCR: *v = smcr_; return true;
    case T_DIER: *v = dier_; return true;
    case T_SR: *v = sr_; return true;
    case T_EGR: *v = 0; return true;
    case T_CCMR1: *v = ccmr1_; return true;
    case T_CCMR2: *v = ccmr2_; return true;
    case T_CCER: *v = ccer_; return true;
    case T_CNT: *v = cnt_; return true;
    case T_PSC: *v = psc_; return true;
    case T_ARR: *v = arr_; return true;
    case T_ECR: *v = ecr_; return true;
    case T_TISEL: *v = tisel_; return true;
    case T_AF1: *v = af1_; return true;
    case T_AF2: *v = af2_; return true;
    case T_DCR: *v = dcr_; return true;
    default:
      if (off >= T_CCR1 && off <= T_CCR4) { *v = ccr_[(off - T_CCR1) / 4u]; return true; }
      return false;
  }
}

bool Tim4::write32(uint32_t off, uint32_t v) {
  switch (off) {
    case T_CR1: {
      const uint32_t sms = field(smcr_, 0u, 3u) | (field(smcr_, 16u, 1u) << 3u);
      if (bit(v, 0u) && sms == 0u && link_) {
        link_->stop(name() + ": CEN with SMS = 0 (counting the internal clock is not modelled; the firmware uses encoder mode)");
        return true;
      }
      cr1_ = (v & ~(1u << 4u)) | (cr1_ & (1u << 4u));
      return true;
    }
    case T_CR2: cr2_ = v; return true;
    case T_SMCR: smcr_ = v; return true;
    case T_DIER: dier_ = v; if (link_) link_->set_irq(IRQ_TIM4, (sr_ & dier_ & 1u) != 0u); return true;
    case T_SR: sr_ &= v; if (link_) link_->set_irq(IRQ_TIM4, (sr_ & dier_ & 1u) != 0u); return true;
    case T_EGR: if (bit(v, 0u)) { cnt_ = 0; if (!bit(cr1_, 2u)) sr_ |= 1u; } return true;
    case T_CCMR1: ccmr1_ = v; return true;
    case T_CCMR2: ccmr2_ = v; return true;
    case T_CCER: ccer_ = v; return true;
    case T_CNT: cnt_ = v & 0xFFFFu; return true;
    case T_PSC: psc_ = v & 0xFFFFu; return true;
    case T_ARR: arr_ = v & 0xFFFFu; return true;
    case T_ECR: ecr_ = v; return true;
    case T_TISEL: tisel_ = v; return true;
    case T_AF1: af1_ = v; return true;
    case T_AF2: af2_ = v; return true;
    case T_DCR: dcr_ = v; return true;
    default:
      if (off >= T_CCR1 && off <= T_CCR4) { ccr_[(off - T_CCR1) / 4u] = v & 0xFFFFu; return true; }
      return false;
  }
}

// --------------------------------------------------------------------------------------------- LPTIM1
namespace {
enum : uint32_t { L_ISR = 0x00, L_ICR = 0x04, L_IER = 0x08, L_CFGR = 0x0C, L_CR = 0x10, L_CMP = 0x14, L_ARR = 0x18, L_CNT = 0x1C, L_OR = 0x20 };
// A write to ARR / CMP crosses into the kernel clock's domain: ARROK / CMPOK after the synchronisation,
// taken here as 3 kernel clock cycles (RM0440 33.4.x describes the flag, not its delay: an assumption).
constexpr double SYNC_KERNEL_CYCLES = 3.0;
}  // namespace

void Lptim1::reset() {
  // SVD: 0 everywhere but ARR 0x00000001.
  isr_ = ier_ = cfgr_ = cr_ = cmp_ = or_ = 0;
  arr_ = 1u;
  counting_ = false;
  count_origin_s_ = 0.0;
  arrok_at_s_ = cmpok_at_s_ = -1.0;
  arrok_cycle_ = UINT64_MAX;
  time_.reset();
}

uint32_t Lptim1::count_now() {
  if (!counting_ || link_ == nullptr) return 0u;
  const double t = time_.sync(link_);
  const double presc = static_cast<double>(1u << field(cfgr_, 9u, 3u));
  const uint64_t n = static_cast<uint64_t>(std::floor((t - count_origin_s_) * kernel_hz_ / presc));
  return static_cast<uint32_t>(n % (static_cast<uint64_t>(arr_) + 1u));
}

void Lptim1::advance() {
  if (link_ == nullptr) return;
  const double t = time_.sync(link_);
  if (arrok_at_s_ >= 0.0 && t >= arrok_at_s_) { isr_ |= 1u << 4u; arrok_at_s_ = -1.0; arrok_cycle_ = UINT64_MAX; }
  if (cmpok_at_s_ >= 0.0 && t >= cmpok_at_s_) { isr_ |= 1u << 3u; cmpok_at_s_ = -1.0; }
  link_->set_irq(IRQ_LPTIM1, (isr_ & ier_ & 0x7Fu) != 0u);
}

uint64_t Lptim1::next_event() const { return arrok_cycle_; }

bool Lptim1::read32(uint32_t off, uint32_t* v) {
  switch (off) {
    case L_ISR: advance(); *v = isr_; return true;
    case L_ICR: *v = 0; return true;
    case L_IER: *v = ier_; return true;
    case L_CFGR: *v = cfgr_; return true;
    case L_CR: *v = cr_; return true;
    case L_CMP: *v = cmp_; return true;
    case L_ARR: *v = arr_; return true;
    case L_CNT: *v = count_now(); return true;
    case L_OR: *v = or_; return true;
    default: return false;
  }
}

bool Lptim1::write32(uint32_t off, uint32_t v) {
  const bool enabled = bit(cr_, 0u);
  const double t = link_ ? time_.sync(link_) : 0.0;
  const double sync_s = SYNC_KERNEL_CYCLES / kernel_hz_;
  switch (off) {
    case L_ICR: isr_ &= ~(v & 0x7Fu); if (link_) link_->set_irq(IRQ_LPTIM1, (isr_ & ier_ & 0x7Fu) != 0u); return true;
    case L_IER:
      if (enabled && link_) { link_->stop(name() + ": IER written while enabled (RM0440 33.7.3: ENABLE = 0)"); return true; }
      ier_ = v & 0x7Fu;
      return true;
    case L_CFGR:
      if (enabled && link_) { link_->stop(name() + ": CFGR written while enabled (RM0440 33.7.4: ENABLE = 0)"); return true; }
      cfgr_ = v;
      return true;
    case L_CR: {
      if (bit(v, 2u) && !bit(v, 0u) && !enabled && link_) {
        link_->stop(name() + ": CNTSTRT with ENABLE = 0 (RM0440 33.7.5)");
        return true;
      }
      cr_ = v & 0x1Fu;
      if (!bit(cr_, 0u)) { counting_ = false; cr_ = 0; return true; }  // disabling resets the counter
      if (bit(v, 2u) && !counting_) { counting_ = true; count_origin_s_ = t; }
      cr_ &= ~((1u << 1u) | (1u << 2u) | (1u << 3u));  // SNGSTRT, CNTSTRT, COUNTRST: set-only
      if (bit(v, 3u)) count_origin_s_ = t;
      return true;
    }
    case L_CMP:
      if (!enabled && link_) { link_->stop(name() + ": CMP written with ENABLE = 0 (RM0440 33.7.6)"); return true; }
      cmp_ = v & 0xFFFFu;
      cmpok_at_s_ = t + sync_s;
      return true;
    case L_ARR:
      if (!enabled && link_) { link_->stop(name() + ": ARR written with ENABLE = 0 (RM0440 33.7.7)"); return true; }
      arr_ = v & 0xFFFFu;
      arrok_at_s_ = t + sync_s;
      if (link_) arrok_cycle_ = link_->cycles() + static_cast<uint64_t>(std::ceil(sync_s * link_->hclk_hz()));
      return true;
    case L_OR: or_ = v; return true;
    default: return false;  // ISR and CNT are read-only
  }
}

}  // namespace vb
