// SPDX-License-Identifier: MIT
// ADC1 and ADC2 as RM0440 section 21 describes them, for what the firmware uses: the power-up sequence
// (21.4.6 DEEPPWD, ADVREGEN and tADCVREG_STUP; 21.4.8 ADCAL; 21.4.9 ADEN / ADRDY), injected sequences
// (21.4.21 JSQR: JL, JEXTSEL, JEXTEN, JSQ1..4) triggered by TIM1's TRGO2, each conversion lasting its
// sampling time (SMPR1/2) + 12.5 ADC clock cycles (21.4.12, 12-bit), JEOC / JEOS and their interrupt
// (ADC1_2, RM0440 table 97), JDR1..4 right-aligned. Regular conversions are not modelled: ADSTART stops the
// board, by name. What the manual forbids stops the board with its reason (link_->stop).
#include <cmath>
#include <string>

#include "access.hpp"
#include "analog.hpp"
#include "models.hpp"

namespace vb {

namespace {
enum : uint32_t {
  ISR = 0x00, IER = 0x04, CR = 0x08, CFGR = 0x0C, CFGR2 = 0x10, SMPR1 = 0x14, SMPR2 = 0x18, TR1 = 0x20,
  TR2 = 0x24, TR3 = 0x28, SQR1 = 0x30, SQR2 = 0x34, SQR3 = 0x38, SQR4 = 0x3C, DR = 0x40, JSQR = 0x4C,
  OFR1 = 0x60, OFR4 = 0x6C, JDR1 = 0x80, JDR4 = 0x8C, AWD2CR = 0xA0, AWD3CR = 0xA4, DIFSEL = 0xB0,
  CALFACT = 0xB4, GCOMP = 0xC0
};
constexpr unsigned ISR_ADRDY = 0, ISR_JEOC = 5, ISR_JEOS = 6;
constexpr unsigned CR_ADEN = 0, CR_ADDIS = 1, CR_ADSTART = 2, CR_JADSTART = 3, CR_ADSTP = 4, CR_JADSTP = 5;
constexpr unsigned CR_ADVREGEN = 28, CR_DEEPPWD = 29, CR_ADCAL = 31;
// DS12589 (STM32G431 datasheet), ADC characteristics: tADCVREG_STUP, the regulator's start-up, 20 us max.
constexpr double T_ADCVREG_STUP_S = 20e-6;
// DS12589 ADC characteristics: tCAL, the calibration, 116 ADC clock cycles.
constexpr uint64_t CAL_ADC_CLOCKS = 116;
// DS12589 ADC characteristics: tSTAB, power-up time, one conversion cycle: the shortest, 2.5 + 12.5 clocks.
constexpr uint64_t STAB_ADC_CLOCKS = 15;
// RM0440 21.4.19 (table "latency between trigger and start of conversion"): 2.5 .. 3 ADC clocks when the
// ADC clock is HCLK-derived (CKMODE != 0); the model uses 3.
constexpr uint64_t TRIGGER_LATENCY_ADC_CLOCKS = 3;
// SMPx codes, RM0440 21.7.6: sampling time in ADC clock cycles x 2.
constexpr uint32_t SMP_HALF_CYCLES[8] = {5, 13, 25, 49, 95, 185, 495, 1281};
constexpr uint32_t JEXTSEL_TIM1_TRGO2 = 8;  // RM0440 table 163, ADC1/ADC2 injected triggers: 01000 = TIM1_TRGO2
}  // namespace

uint32_t Adc12Common::hclk_per_adc_clock() const {
  // RM0440 21.7.29 ADC_CCR CKMODE: 00 asynchronous (RCC's ADC12SEL), 01 HCLK/1, 10 HCLK/2, 11 HCLK/4.
  switch (field(ccr_, 16u, 2u)) {
    case 1: return 1;
    case 2: return 2;
    case 3: return 4;
    default: return 0;
  }
}

bool Adc12Common::read32(uint32_t off, uint32_t* v) {
  switch (off) {
    case 0x00: *v = 0; return true;  // ADC12_CSR: the masters' and slaves' flags (not used by the firmware)
    case 0x08: *v = ccr_; return true;
    case 0x0C: *v = 0; return true;  // CDR: dual mode only
    default: return false;
  }
}

bool Adc12Common::write32(uint32_t off, uint32_t v) {
  if (off == 0x08) { ccr_ = v & 0x01FFEFFFu; return true; }
  return false;
}

void Adc::reset() {
  // SVD reset values: CR 0x20000000 (DEEPPWD), CFGR 0x80000000 (JQDIS), TR1 0x0FFF0000, TR2 / TR3 0x00FF0000.
  isr_ = ier_ = cfgr2_ = smpr1_ = smpr2_ = dr_ = jsqr_ = awd2cr_ = awd3cr_ = difsel_ = gcomp_ = 0;
  calfact_ = 0;
  cr_ = 0x20000000u;
  cfgr_ = 0x80000000u;
  tr1_ = 0x0FFF0000u;
  tr2_ = tr3_ = 0x00FF0000u;
  for (auto& s : sqr_) s = 0;
  for (auto& o : ofr_) o = 0;
  for (auto& j : jdr_) j = 0;
  regulator_on_s_ = -1.0;
  cal_done_ = ready_at_ = UINT64_MAX;
  ready_ = false;
  seq_len_ = seq_next_ = 0;
  time_.reset();
}

bool Adc::regulator_ready() const {
  if (regulator_on_s_ < 0.0 || link_ == nullptr) return false;
  return const_cast<TimeBase&>(time_).sync(link_) - regulator_on_s_ >= T_ADCVREG_STUP_S;
}

uint64_t Adc::conversion_cycles(uint32_t channel) const {
  const uint32_t smpr = channel < 10u ? smpr1_ : smpr2_;
  const uint32_t smp = field(smpr, 3u * (channel % 10u), 3u);
  const uint64_t half_clocks = SMP_HALF_CYCLES[smp] + 25u;  // + 12.5 cycles of successive approximation
  const uint32_t div = common_ ? common_->hclk_per_adc_clock() : 0u;
  return (half_clocks * div + 1u) / 2u;
}

void Adc::update_irq() {
  if (link_ == nullptr) return;
  const bool level = irq_level() || (partner_ != nullptr && partner_->irq_level());
  link_->set_irq(IRQ_ADC1_2, level);
}

uint32_t Adc::sample(uint32_t channel) {
  double v = 0.0;
  bool driven = plant_ != nullptr && plant_->adc_input(index_, channel, &v);
  if (!driven) v = 0.0;  // nothing drives the input: the sampling capacitor discharges to 0 (modelled as 0)
  const double vref = plant_ ? plant_->vdda() : 3.3;
  // Ideal 12-bit transfer, RM0440 21.4.16: code = V x 4096 / VREF+, plus the seeded noise.
  double code = std::floor(v * 4096.0 / vref + (plant_ ? plant_->adc_noise() : 0.0) + 0.5);
  if (code < 0.0) code = 0.0;
  if (code > 4095.0) code = 4095.0;
  return static_cast<uint32_t>(code);
}

void Adc::trigger(uint64_t cycle) {
  if (!bit(cr_, CR_JADSTART) || !bit(cr_, CR_ADEN)) return;
  const uint32_t jexten = field(jsqr_, 7u, 2u), jextsel = field(jsqr_, 2u, 5u);
  if (jexten != 1u && jexten != 3u) return;  // rising (or both) edges only: TRGO2 gives rising edges
  if (jextsel != JEXTSEL_TIM1_TRGO2) return;
  if (seq_next_ < seq_len_) return;          // RM0440 21.4.21: a trigger during an injected sequence is ignored
  const uint32_t div = common_ ? common_->hclk_per_adc_clock() : 0u;
  seq_jsqr_ = jsqr_;
  seq_len_ = static_cast<int>(field(jsqr_, 0u, 2u)) + 1;
  seq_next_ = 0;
  uint64_t t = cycle + TRIGGER_LATENCY_ADC_CLOCKS * div;
  static const unsigned pos[4] = {9u, 15u, 21u, 27u};
  for (int r = 0; r < seq_len_; ++r) {
    const uint32_t ch = field(seq_jsqr_, pos[r], 5u);
    // The input is held at the start of its sampling: the plant and the bridge as they are at cycle t.
    seq_code_[r] = sample_at(ch, t);
    t += conversion_cycles(ch);
    seq_end_[r] = t;
  }
}

uint32_t Adc::sample_at(uint32_t channel, uint64_t cycle) {
  if (plant_ != nullptr) plant_->set_sample_cycle(cycle);
  return sample(channel);
}

void Adc::advance() {
  if (link_ == nullptr) return;
  const uint64_t now = link_->cycles();
  if (cal_done_ <= now) {
    cr_ &= ~(1u << CR_ADCAL);
    calfact_ = 0x00400040u;  // a calibration factor (the value is the silicon's; any the firmware keeps)
    cal_done_ = UINT64_MAX;
  }
  if (ready_at_ <= now) {
    isr_ |= 1u << ISR_ADRDY;
    ready_ = true;
    ready_at_ = UINT64_MAX;
  }
  while (seq_next_ < seq_len_ && seq_end_[seq_next_] <= now) {
    jdr_[seq_next_] = seq_code_[seq_next_];
    isr_ |= 1u << ISR_JEOC;
    ++seq_next_;
    if (seq_next_ == seq_len_) isr_ |= 1u << ISR_JEOS;
  }
  update_irq();
}

uint64_t Adc::next_event() const {
  uint64_t t = std::min(cal_done_, ready_at_);
  // Each rank's end is an event when JEOCIE asks for its interrupt; otherwise only the sequence's end (the
  // flags and JDRx of the ranks between are caught up before each read).
  if (seq_next_ < seq_len_) t = std::min(t, bit(ier_, ISR_JEOC) ? seq_end_[seq_next_] : seq_end_[seq_len_ - 1]);
  return t;
}

bool Adc::read32(uint32_t off, uint32_t* v) {
  if (off == ISR || off == CR || (off >= JDR1 && off <= JDR4)) advance();  // as of now
  switch (off) {
    case ISR: *v = isr_; return true;
    case IER: *v = ier_; return true;
    case CR: *v = cr_; return true;
    case CFGR: *v = cfgr_; return true;
    case CFGR2: *v = cfgr2_; return true;
    case SMPR1: *v = smpr1_; return true;
    case SMPR2: *v = smpr2_; return true;
    case TR1: *v = tr1_; return true;
    case TR2: *v = tr2_; return true;
    case TR3: *v = tr3_; return true;
    case SQR1: case SQR2: case SQR3: case SQR4: *v = sqr_[(off - SQR1) / 4u]; return true;
    case DR: *v = dr_; return true;
    case JSQR: *v = jsqr_; return true;
    case AWD2CR: *v = awd2cr_; return true;
    case AWD3CR: *v = awd3cr_; return true;
    case DIFSEL: *v = difsel_; return true;
    case CALFACT: *v = calfact_; return true;
    case GCOMP: *v = gcomp_; return true;
    default:
      if (off >= OFR1 && off <= OFR4) { *v = ofr_[(off - OFR1) / 4u]; return true; }
      if (off >= JDR1 && off <= JDR4) { *v = jdr_[(off - JDR1) / 4u]; return true; }
      return false;
  }
}

bool Adc::write32(uint32_t off, uint32_t v) {
  const std::string me = name();
  const bool conv = bit(cr_, CR_ADSTART) || bit(cr_, CR_JADSTART);
  switch (off) {
    case ISR: isr_ &= ~v; update_irq(); return true;  // rc_w1
    case IER: ier_ = v & 0x7FFu; update_irq(); return true;
    case CR: {
      const uint32_t old = cr_;
      const bool cal_running = bit(old, CR_ADCAL);
      // rw bits: ADVREGEN, DEEPPWD, ADCALDIF (bits 28..30): writable only with ADEN clear (RM0440 21.7.3).
      const uint32_t rw = 0x70000000u;
      if ((v & rw) != (old & rw)) {
        if (bit(old, CR_ADEN)) { link_->stop(me + ": ADVREGEN / DEEPPWD / ADCALDIF written with ADEN set (RM0440 21.7.3)"); return true; }
        cr_ = (cr_ & ~rw) | (v & rw);
        if (bit(cr_, CR_DEEPPWD) && bit(cr_, CR_ADVREGEN)) {
          link_->stop(me + ": ADVREGEN set in deep power-down (DEEPPWD = 1; RM0440 21.4.6: clear DEEPPWD first)");
          return true;
        }
        if (bit(cr_, CR_ADVREGEN) && !bit(old, CR_ADVREGEN)) regulator_on_s_ = time_.sync(link_);
        if (!bit(cr_, CR_ADVREGEN)) regulator_on_s_ = -1.0;
      }
      const uint32_t div = common_ ? common_->hclk_per_adc_clock() : 0u;
      const uint64_t now = link_->cycles();
      if (bit(v, CR_ADCAL) && !cal_running) {
        if (bit(cr_, CR_ADEN)) { link_->stop(me + ": ADCAL set with ADEN = 1 (RM0440 21.4.8: calibrate a disabled ADC)"); return true; }
        if (!regulator_ready()) { link_->stop(me + ": ADCAL set before the voltage regulator's start-up time tADCVREG_STUP (20 us, DS12589) since ADVREGEN"); return true; }
        if (div == 0u) { link_->stop(me + ": ADCAL with CKMODE = 0 (the asynchronous ADC clock from RCC is not modelled)"); return true; }
        cr_ |= 1u << CR_ADCAL;
        cal_done_ = now + CAL_ADC_CLOCKS * div;
      }
      if (bit(v, CR_ADEN) && !bit(cr_, CR_ADEN)) {
        if (bit(cr_, CR_ADCAL)) { link_->stop(me + ": ADEN set during calibration (ADCAL = 1; RM0440 21.4.9)"); return true; }
        if (!regulator_ready()) { link_->stop(me + ": ADEN set before the voltage regulator is ready (tADCVREG_STUP since ADVREGEN; RM0440 21.4.6)"); return true; }
        if (div == 0u) { link_->stop(me + ": ADEN with CKMODE = 0 (the asynchronous ADC clock from RCC is not modelled)"); return true; }
        cr_ |= 1u << CR_ADEN;
        ready_at_ = now + STAB_ADC_CLOCKS * div;
      }
      if (bit(v, CR_ADDIS) && bit(cr_, CR_ADEN)) {
        if (conv) { link_->stop(me + ": ADDIS while a conversion is on (RM0440 21.4.9: stop it first)"); return true; }
        cr_ &= ~(1u << CR_ADEN);
        ready_ = false;
      }
      if (bit(v, CR_JADSTART) && !bit(cr_, CR_JADSTART)) {
        // The ADC is ready once ADRDY has come (the flag itself may have been cleared by software since).
        if (!bit(cr_, CR_ADEN) || !ready_ || bit(cr_, CR_ADDIS)) {
          link_->stop(me + ": JADSTART set before the ADC is ready (RM0440 21.4.20: only with ADEN = 1, ADRDY come, ADDIS = 0)");
          return true;
        }
        cr_ |= 1u << CR_JADSTART;
      }
      if (bit(v, CR_JADSTP)) { cr_ &= ~(1u << CR_JADSTART); seq_len_ = seq_next_ = 0; }
      if (bit(v, CR_ADSTART)) { link_->stop(me + ": ADSTART: regular conversions are not modelled"); return true; }
      (void)CR_ADSTP;
      return true;
    }
    case CFGR:
      if (conv) { link_->stop(me + ": CFGR written during a conversion (RM0440 21.7.4: ADSTART = JADSTART = 0)"); return true; }
      cfgr_ = v;
      return true;
    case CFGR2: cfgr2_ = v; return true;
    case SMPR1: case SMPR2:
      if (conv) { link_->stop(me + ": SMPR written during a conversion (RM0440 21.7.6: ADSTART = JADSTART = 0)"); return true; }
      (off == SMPR1 ? smpr1_ : smpr2_) = v & (off == SMPR1 ? 0xBFFFFFFFu : 0x07FFFFFFu);
      return true;
    case TR1: tr1_ = v; return true;
    case TR2: tr2_ = v; return true;
    case TR3: tr3_ = v; return true;
    case SQR1: case SQR2: case SQR3: case SQR4: sqr_[(off - SQR1) / 4u] = v; return true;
    case JSQR: jsqr_ = v; return true;
    case AWD2CR: awd2cr_ = v; return true;
    case AWD3CR: awd3cr_ = v; return true;
    case DIFSEL: difsel_ = v; return true;
    case CALFACT: calfact_ = v; return true;
    case GCOMP: gcomp_ = v; return true;
    default:
      if (off >= OFR1 && off <= OFR4) { ofr_[(off - OFR1) / 4u] = v; return true; }
      return false;  // DR and JDRx are read-only: a write is not a register the model covers
  }
}

}  // namespace vb
