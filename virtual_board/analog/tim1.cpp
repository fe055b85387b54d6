// SPDX-License-Identifier: MIT
// TIM1 as RM0440 section 28 describes it, for what the B-G431B-ESC1's bridge needs: the centre-aligned
// counter (CMS 1..3: 0 up to ARR, down to 0, a period of 2 x ARR ticks of CK_CNT = f / (PSC + 1)),
// preloaded ARR / PSC / CCRx / RCR taken at the update event (each over- and underflow in centre-aligned
// mode, thinned by RCR), OCxREF in PWM modes 1 and 2, TRGO2 (MMS2) to the ADCs, the dead time (DTG), and
// the break: the comparators selected in TIM1_AF1 clear MOE and set BIF with no software involved; with MOE
// clear the outputs take their idle levels (OISx, OISxN).
// Timer clock: HCLK (APB2 prescaler 1 as the firmware sets it, so the timer clock x1 of RM0440 RCC
// section 7.2.15 is HCLK); the cycles of BoardLink are HCLK cycles.
#include <algorithm>

#include "access.hpp"
#include "analog.hpp"
#include "models.hpp"

namespace vb {

namespace {
// Offsets, RM0440 28.6.29 (TIM1 register map).
enum : uint32_t {
  CR1 = 0x00, CR2 = 0x04, SMCR = 0x08, DIER = 0x0C, SR = 0x10, EGR = 0x14, CCMR1 = 0x18, CCMR2 = 0x1C,
  CCER = 0x20, CNT = 0x24, PSC = 0x28, ARR = 0x2C, RCR = 0x30, CCR1 = 0x34, CCR2 = 0x38, CCR3 = 0x3C,
  CCR4 = 0x40, BDTR = 0x44, CCR5 = 0x48, CCR6 = 0x4C, CCMR3 = 0x50, DTR2 = 0x54, ECR = 0x58, TISEL = 0x5C,
  AF1 = 0x60, AF2 = 0x64, OR1 = 0x68, DCR = 0x3DC, DMAR = 0x3E0
};
constexpr unsigned CR1_CEN = 0, CR1_URS = 2, CR1_CMS = 5, CR1_ARPE = 7;
constexpr unsigned BDTR_BKE = 12, BDTR_BKP = 13, BDTR_AOE = 14, BDTR_MOE = 15;
constexpr unsigned SR_UIF = 0, SR_BIF = 7;
constexpr unsigned EGR_UG = 0, EGR_BG = 7;
constexpr unsigned DIER_UIE = 0, DIER_BIE = 7;

// OCxM of channel ch (0..5): 4 bits split over the CCMR's [6:4] and [16].
uint32_t ocm(uint32_t ccmr1, uint32_t ccmr2, uint32_t ccmr3, int ch) {
  const uint32_t r = ch < 2 ? ccmr1 : (ch < 4 ? ccmr2 : ccmr3);
  const unsigned base = (ch % 2) ? 8u : 0u;
  return field(r, base + 4u, 3u) | (field(r, base + 16u, 1u) << 3u);
}
}  // namespace

void Tim1::reset() {
  // The stm32g4 crate's SVD reset values: 0 everywhere but ARR 0xFFFF. (RM0440's TIM1_AF1 / AF2 tables give
  // BKINE / BK2INE set at reset, as I read them; the SVD gives 0 and the brief asks for the SVD: 0 here. Either
  // way the BKIN pin is not routed on this board, so the break sources are the comparators alone.)
  cr1_ = cr2_ = smcr_ = dier_ = sr_ = ccmr1_ = ccmr2_ = ccmr3_ = ccer_ = 0;
  psc_ = rcr_ = bdtr_ = dtr2_ = ecr_ = tisel_ = or1_ = dcr_ = 0;
  arr_ = 0xFFFFu;
  af1_ = af2_ = 0u;
  ccr_.fill(0);
  ccr_active_.fill(0);
  arr_active_ = 0xFFFFu;
  psc_active_ = rcr_active_ = 0;
  running_ = false;
  start_ = 0;
  periods_done_ = 0;
  next_trgo2_ = UINT64_MAX;
  cnt_stopped_ = 0;
  rep_ = 0;
  next_half_ = UINT64_MAX;
  break_active_ = false;
  raise_irqs();
}

void Tim1::add_trgo2_sink(Trgo2Sink fn, void* ctx) {
  if (nsinks_ < static_cast<int>(sinks_.size())) {
    sinks_[static_cast<size_t>(nsinks_)] = fn;
    sink_ctx_[static_cast<size_t>(nsinks_)] = ctx;
    ++nsinks_;
  }
}

bool Tim1::centre_aligned() const { return field(cr1_, CR1_CMS, 2u) != 0u; }

uint32_t Tim1::period_ticks() const {
  const uint32_t a = arr_active_ == 0u ? 1u : arr_active_;
  return centre_aligned() ? 2u * a : a + 1u;
}

uint64_t Tim1::cycles_per_period() const { return static_cast<uint64_t>(period_ticks()) * tick_cycles(); }

uint64_t Tim1::pos_ticks_at(uint64_t cycle) const {
  if (!running_ || cycle < start_) return 0;
  return ((cycle - start_) / tick_cycles()) % period_ticks();
}

uint64_t Tim1::pos_ticks() const { return pos_ticks_at(link_ ? link_->cycles() : 0u); }

uint32_t Tim1::count_at(uint64_t cycle) const {
  if (!running_) return cnt_stopped_;
  const uint64_t p = pos_ticks_at(cycle);
  if (!centre_aligned()) return static_cast<uint32_t>(p);
  return static_cast<uint32_t>(p <= arr_active_ ? p : 2u * arr_active_ - p);
}

uint32_t Tim1::count() const { return count_at(link_ ? link_->cycles() : 0u); }

bool Tim1::counting_up() const {
  if (!running_ || !centre_aligned()) return true;
  return pos_ticks() < arr_active_;
}

// OCxREF of channel ch at a counter position.
bool Tim1::ref_at(int ch, uint64_t cycle) const {
  const uint32_t m = ocm(ccmr1_, ccmr2_, ccmr3_, ch);
  const uint32_t c = count_at(cycle);
  const bool up = !running_ || !centre_aligned() || pos_ticks_at(cycle) < arr_active_;
  const uint32_t ccr = ccr_active_[static_cast<size_t>(ch)];
  // PWM mode 1: up, active while CNT < CCR; down, inactive while CNT > CCR (RM0440 28.3.14).
  const bool pwm1 = up ? (c < ccr) : (c <= ccr);
  switch (m) {
    case 4: return false;  // forced inactive
    case 5: return true;   // forced active
    case 6: return pwm1;
    case 7: return !pwm1;  // PWM mode 2
    default: return false; // frozen and the compare-match modes: the bridge's channels never use them
  }
}

bool Tim1::outputs_enabled() const {
  if (!moe()) return false;
  for (int k = 0; k < 3; ++k) {
    const unsigned u = static_cast<unsigned>(k);
    if (!bit(ccer_, 4u * u) || !bit(ccer_, 4u * u + 2u)) return false;  // CCxE and CCxNE
  }
  return true;
}

double Tim1::duty(int phase) const {
  // The high side's share of one period. PWM1, centre-aligned: on while CNT < CCR counting up and
  // CNT <= CCR counting down: (2 x CCR) / (2 x ARR) ticks; clamped at 0 and 1.
  const uint32_t m = ocm(ccmr1_, ccmr2_, ccmr3_, phase);
  const double a = arr_active_ == 0u ? 1.0 : static_cast<double>(arr_active_);
  double d = std::min(1.0, static_cast<double>(ccr_active_[static_cast<size_t>(phase)]) / a);
  if (!centre_aligned()) d = std::min(1.0, ccr_active_[static_cast<size_t>(phase)] / (a + 1.0));
  switch (m) {
    case 4: return 0.0;
    case 5: return 1.0;
    case 6: return d;
    case 7: return 1.0 - d;
    default: return 0.0;
  }
}

bool Tim1::low_side_on_at(int phase, uint64_t cycle) const {
  const unsigned u = static_cast<unsigned>(phase);
  if (!moe() || !bit(ccer_, 4u * u + 2u)) return bit(cr2_, 9u + 2u * u) && !moe();  // OISxN at idle
  // CHxN is the complement of OCxREF (CCxNP = 0), delayed by the dead time at its rising edge: the
  // dead time is a few ticks of 4250, so at the sampling instant the complement is what counts.
  return !ref_at(phase, cycle);
}

bool Tim1::low_side_on(int phase) const { return low_side_on_at(phase, link_ ? link_->cycles() : 0u); }

uint32_t Tim1::deadtime_ticks() const {
  // RM0440 28.6.21 DTG[7:0]: t_DTS units (CKD = 0: t_DTS = t_CK_INT).
  const uint32_t dtg = field(bdtr_, 0u, 8u);
  if ((dtg & 0x80u) == 0u) return dtg;
  if ((dtg & 0xC0u) == 0x80u) return (64u + (dtg & 0x3Fu)) * 2u;
  if ((dtg & 0xE0u) == 0xC0u) return (32u + (dtg & 0x1Fu)) * 8u;
  return (32u + (dtg & 0x1Fu)) * 16u;
}

void Tim1::update_event(bool software) {
  // RM0440 28.3.3: the preload registers go to their shadows.
  if (bit(cr1_, CR1_ARPE) || software) arr_active_ = arr_;
  psc_active_ = psc_;
  rcr_active_ = rcr_;
  rep_ = rcr_active_;
  for (int k = 0; k < 6; ++k) {
    const uint32_t r = k < 2 ? ccmr1_ : (k < 4 ? ccmr2_ : ccmr3_);
    const bool preload = bit(r, (k % 2) ? 11u : 3u);  // OCxPE
    if (preload || software) ccr_active_[static_cast<size_t>(k)] = ccr_[static_cast<size_t>(k)];
  }
  if (!(software && bit(cr1_, CR1_URS))) sr_ |= 1u << SR_UIF;
}

void Tim1::schedule() {
  next_trgo2_ = UINT64_MAX;
  next_half_ = UINT64_MAX;
  if (!running_ || link_ == nullptr) return;
  const uint64_t now = link_->cycles();
  const uint64_t tc = tick_cycles();
  const uint64_t per = cycles_per_period();
  const uint64_t base = start_ + ((now - start_) / per) * per;  // this period's start
  // Half-period boundaries (centre-aligned: over- and underflow; edge-aligned: the overflow).
  const uint64_t half = centre_aligned() ? static_cast<uint64_t>(arr_active_) * tc : per;
  uint64_t h = base;
  while (h <= now) h += half;
  next_half_ = h;
  // TRGO2 (MMS2, RM0440 28.6.2): 7 = OC4REF rising; 2 = the update event.
  const uint32_t mms2 = field(cr2_, 20u, 4u);
  if (mms2 == 7u && centre_aligned()) {
    const uint32_t c4 = ccr_active_[3];
    if (c4 > 0u && c4 < arr_active_) {
      uint64_t t = base + (2u * static_cast<uint64_t>(arr_active_) - c4) * tc;  // counting down, CNT = CCR4
      if (t <= now) t += per;
      next_trgo2_ = t;
    }
  } else if (mms2 == 2u) {
    next_trgo2_ = next_half_;
  }
}

void Tim1::advance() {
  if (link_ == nullptr) return;
  const uint64_t now = link_->cycles();
  while (running_ && (next_half_ <= now || next_trgo2_ <= now)) {
    if (next_trgo2_ <= next_half_) {
      const uint64_t t = next_trgo2_;
      for (int i = 0; i < nsinks_; ++i) sinks_[static_cast<size_t>(i)](sink_ctx_[static_cast<size_t>(i)], t);
      next_trgo2_ = UINT64_MAX;
      if (next_half_ == t) continue;
    }
    if (next_half_ <= now) {
      if (rep_ == 0u) {
        update_event(false);
      } else {
        --rep_;
      }
      const uint64_t h = next_half_;
      // schedule() from just after this boundary
      next_half_ = UINT64_MAX;
      const uint64_t tc = tick_cycles();
      const uint64_t per = cycles_per_period();
      const uint64_t half = centre_aligned() ? static_cast<uint64_t>(arr_active_) * tc : per;
      next_half_ = h + half;
      // the next TRGO2 after h
      const uint32_t mms2 = field(cr2_, 20u, 4u);
      if (mms2 == 7u && centre_aligned()) {
        const uint32_t c4 = ccr_active_[3];
        if (c4 > 0u && c4 < arr_active_ && next_trgo2_ == UINT64_MAX) {
          const uint64_t base = start_ + ((h - start_) / per) * per;
          uint64_t t = base + (2u * static_cast<uint64_t>(arr_active_) - c4) * tc;
          if (t <= h) t += per;
          next_trgo2_ = t;
        }
      } else if (mms2 == 2u) {
        next_trgo2_ = next_half_;
      }
    }
  }
  if (plant_ != nullptr) plant_->step_to_cycle(link_);
  raise_irqs();
}

uint64_t Tim1::next_event() const {
  // The update events are an event for the board only when their interrupt is enabled: the preload's
  // transfer and UIF are caught up on each advance() and before each read of the timer's registers.
  uint64_t t = bit(dier_, DIER_UIE) ? std::min(next_half_, next_trgo2_) : next_trgo2_;
  if (plant_ != nullptr && link_ != nullptr) t = std::min(t, plant_->next_step_cycle(link_));
  return t;
}

uint32_t Tim1::merge_base(uint32_t off, uint32_t current) const {
  if (off == SR) return 0xFFFFFFFFu;  // rc_w0: the other lanes write 1, no effect
  if (off == EGR) return 0u;          // an event only where a 1 is written
  return current;
}

void Tim1::break_inputs_changed() {
  // RM0440 28.3.19: the break input is the OR of the enabled sources, each through its polarity
  // (AF1 BKCMPxP), then BKP gives the active level.
  bool in = false;
  if (comps_ != nullptr) {
    for (int k = 0; k < 4; ++k) {
      const unsigned u = static_cast<unsigned>(k);
      if (bit(af1_, 1u + u)) in = in || (comps_->output(k) != bit(af1_, 10u + u));
    }
  }
  // BKINE (AF1 bit 0, set at reset): the BKIN pin; no GPIO routes it on this board, so it is low.
  const bool active = bit(bdtr_, BDTR_BKE) && (in == bit(bdtr_, BDTR_BKP));
  if (active) do_break();
  break_active_ = active;
}

void Tim1::do_break() {
  bdtr_ &= ~(1u << BDTR_MOE);
  sr_ |= 1u << SR_BIF;
  raise_irqs();
}

void Tim1::raise_irqs() {
  if (link_ == nullptr) return;
  link_->set_irq(IRQ_TIM1_UP, bit(sr_, SR_UIF) && bit(dier_, DIER_UIE));
  link_->set_irq(IRQ_TIM1_BRK, (bit(sr_, SR_BIF) || bit(sr_, 8u)) && bit(dier_, DIER_BIE));
  link_->set_irq(IRQ_TIM1_CC, (sr_ & dier_ & 0x1Eu) != 0u);
  link_->set_irq(IRQ_TIM1_TRG_COM, (sr_ & dier_ & 0x60u) != 0u);
}

bool Tim1::read32(uint32_t off, uint32_t* v) {
  if (off == SR) advance();  // UIF and BIF as of now
  switch (off) {
    case CR1: *v = cr1_ | (counting_up() ? 0u : 1u << 4u); return true;  // DIR read-only in centre-aligned
    case CR2: *v = cr2_; return true;
    case SMCR: *v = smcr_; return true;
    case DIER: *v = dier_; return true;
    case SR: *v = sr_; return true;
    case EGR: *v = 0; return true;
    case CCMR1: *v = ccmr1_; return true;
    case CCMR2: *v = ccmr2_; return true;
    case CCMR3: *v = ccmr3_; return true;
    case CCER: *v = ccer_; return true;
    case CNT: *v = count(); return true;
    case PSC: *v = psc_; return true;
    case ARR: *v = arr_; return true;
    case RCR: *v = rcr_; return true;
    case CCR1: case CCR2: case CCR3: case CCR4: *v = ccr_[(off - CCR1) / 4u]; return true;
    case CCR5: *v = ccr_[4]; return true;
    case CCR6: *v = ccr_[5]; return true;
    case BDTR: *v = bdtr_; return true;
    case DTR2: *v = dtr2_; return true;
    case ECR: *v = ecr_; return true;
    case TISEL: *v = tisel_; return true;
    case AF1: *v = af1_; return true;
    case AF2: *v = af2_; return true;
    case OR1: *v = or1_; return true;
    case DCR: *v = dcr_; return true;
    default: return false;
  }
}

bool Tim1::write32(uint32_t off, uint32_t v) {
  switch (off) {
    case CR1: {
      const bool was = bit(cr1_, CR1_CEN);
      cr1_ = v & 0x1BFFu & ~(1u << 4u);
      if (!was && bit(cr1_, CR1_CEN)) {
        running_ = true;
        const uint64_t now = link_ ? link_->cycles() : 0u;
        // The count resumes from CNT: rebase so that the position maps to it (counting up).
        start_ = now - static_cast<uint64_t>(cnt_stopped_) * tick_cycles();
        if (now < static_cast<uint64_t>(cnt_stopped_) * tick_cycles()) start_ = 0;
      } else if (was && !bit(cr1_, CR1_CEN)) {
        cnt_stopped_ = count();
        running_ = false;
      }
      schedule();
      return true;
    }
    case CR2: cr2_ = v & 0x00F7FFFDu; schedule(); return true;
    case SMCR: smcr_ = v; return true;
    case DIER: dier_ = v & 0x00F07FFFu; raise_irqs(); return true;
    case SR: sr_ &= v; raise_irqs(); return true;  // rc_w0
    case EGR:
      if (bit(v, EGR_UG)) {
        update_event(true);
        cnt_stopped_ = 0;
        if (running_ && link_) start_ = link_->cycles();
        schedule();
      }
      if (bit(v, EGR_BG) && bit(bdtr_, BDTR_BKE)) do_break();
      raise_irqs();
      return true;
    case CCMR1: ccmr1_ = v; return true;
    case CCMR2: ccmr2_ = v; return true;
    case CCMR3: ccmr3_ = v; return true;
    case CCER: ccer_ = v; return true;
    case CNT:
      cnt_stopped_ = v & 0xFFFFu;
      if (running_ && link_) {
        const uint64_t now = link_->cycles();
        start_ = now - std::min<uint64_t>(now, static_cast<uint64_t>(cnt_stopped_) * tick_cycles());
        schedule();
      }
      return true;
    case PSC: psc_ = v & 0xFFFFu; return true;
    case ARR:
      arr_ = v & 0xFFFFu;
      if (!bit(cr1_, CR1_ARPE)) { arr_active_ = arr_; schedule(); }
      return true;
    case RCR: rcr_ = v & 0xFFFFu; return true;
    case CCR1: case CCR2: case CCR3: case CCR4: case CCR5: case CCR6: {
      const size_t k = off <= CCR4 ? (off - CCR1) / 4u : (off == CCR5 ? 4u : 5u);
      ccr_[k] = v & (k == 4 ? 0xE00FFFFFu : 0xFFFFu);
      const uint32_t r = k < 2 ? ccmr1_ : (k < 4 ? ccmr2_ : ccmr3_);
      if (!bit(r, (k % 2) ? 11u : 3u)) { ccr_active_[k] = ccr_[k]; schedule(); }
      return true;
    }
    case BDTR: {
      // MOE: software may set it, but not while the break input is active (RM0440 28.3.19).
      uint32_t nv = v;
      if (break_active_ && bit(nv, BDTR_MOE)) nv &= ~(1u << BDTR_MOE);
      bdtr_ = nv;
      break_inputs_changed();
      (void)BDTR_AOE;
      return true;
    }
    case DTR2: dtr2_ = v; return true;
    case ECR: ecr_ = v; return true;
    case TISEL: tisel_ = v; return true;
    case AF1: af1_ = v; break_inputs_changed(); return true;
    case AF2: af2_ = v; return true;
    case OR1: or1_ = v; return true;
    case DCR: dcr_ = v; return true;
    default: return false;
  }
}

}  // namespace vb
