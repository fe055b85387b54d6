// SPDX-License-Identifier: MIT
// OPAMP1..3 (RM0440 section 25), COMP1..4 (section 24) and DAC3 (section 22): the over-current trip's
// chain. The shunt network's voltage reaches both the op-amp's VINP0 and the comparator's INP pin; DAC3's
// channels give the comparators' thresholds on INM; the comparators' outputs feed TIM1's break.
#include <cmath>
#include <string>

#include "access.hpp"
#include "analog.hpp"
#include "models.hpp"

namespace vb {

// ---------------------------------------------------------------------------------------------- OPAMP
void Opamps::reset() {
  csr_.fill(0);  // SVD: OPAMPx_CSR and OPAMPx_TCMR reset 0
  tcmr_.fill(0);
}

bool Opamps::output(int k, double* volts) const {
  const uint32_t c = csr_[static_cast<size_t>(k)];
  if (!bit(c, 0u) || plant_ == nullptr) return false;  // OPAEN clear: the output is off (high impedance)
  const double vdda = plant_->vdda();
  // VP_SEL (RM0440 25.5.1): 00 VINP0 (PA1 / PA7 / PB0: the shunt networks), others pins the board leaves
  // to other parts (0 V here) or DAC channels the firmware does not route.
  const double vp = field(c, 2u, 2u) == 0u ? plant_->shunt_vinp(k) : 0.0;
  const double vm0 = plant_->vinm0(k);
  double out = 0.0;
  switch (field(c, 5u, 2u)) {  // VM_SEL
    case 0:  // VINM0 pin: no feedback, open loop: the output goes to a rail
      out = vp > vm0 ? vdda : 0.0;
      break;
    case 1:  // VINM1 pin (not wired on the board: held at 0 V here), open loop
      out = vp > 0.0 ? vdda : 0.0;
      break;
    case 2: {  // PGA: PGA_GAIN[2:0] = 2 << n; [4:3] how the gain network's foot is tied
      const uint32_t g = field(c, 14u, 5u);
      if ((g & 7u) > 5u) return false;  // reserved gains: no defined output
      const double gain = static_cast<double>(2u << (g & 7u));
      switch (g >> 3u) {
        case 0: out = gain * vp; break;                           // foot to ground internally
        case 1: out = gain * vp - (gain - 1.0) * vm0; break;      // foot on VINM0: input / bias
        case 2: out = gain * vp; break;                           // VINM0 for filtering only
        default: out = gain * vp; break;                          // VINM1 bias / filtering (VINM1 at 0 V)
      }
      break;
    }
    default: out = vp; break;  // follower
  }
  // The output swings between the rails (DS12589 OPAMP VOHSAT / VOLSAT: within about 100 mV; the rails here).
  *volts = std::fmin(std::fmax(out, 0.0), vdda);
  return true;
}

bool Opamps::read32(uint32_t off, uint32_t* v) {
  if (off <= 0x08u) { *v = csr_[off / 4u]; return true; }
  if (off >= 0x18u && off <= 0x20u) { *v = tcmr_[(off - 0x18u) / 4u]; return true; }
  return false;  // OPAMP4..6 (0x0C..0x14) do not exist on the STM32G431
}

bool Opamps::write32(uint32_t off, uint32_t v) {
  if (off <= 0x08u) {
    uint32_t& c = csr_[off / 4u];
    if (bit(c, 31u)) return true;  // LOCK: read-only until reset
    c = v & ~(1u << 30u);         // CALOUT is read-only
    return true;
  }
  if (off >= 0x18u && off <= 0x20u) { tcmr_[(off - 0x18u) / 4u] = v; return true; }
  return false;
}

// ----------------------------------------------------------------------------------------------- DAC3
namespace {
enum : uint32_t {
  DCR = 0x00, SWTRGR = 0x04, DHR12R1 = 0x08, DHR12L1 = 0x0C, DHR8R1 = 0x10, DHR12R2 = 0x14, DHR12L2 = 0x18,
  DHR8R2 = 0x1C, DHR12RD = 0x20, DHR12LD = 0x24, DHR8RD = 0x28, DOR1 = 0x2C, DOR2 = 0x30, DSR = 0x34,
  DCCR = 0x38, MCR = 0x3C, SHSR1 = 0x40, SHSR2 = 0x44, SHHR = 0x48, SHRR = 0x4C, STR1 = 0x58, STR2 = 0x5C,
  STMODR = 0x60
};
// The DAC's wake-up from ENx until DACxRDY: DS12589 gives tWAKEUP for the DACs (a few us); the model uses
// 7.5 us, an assumption of that order, not a figure read from the table for DAC3's internal channels.
constexpr double DAC_WAKEUP_S = 7.5e-6;
}  // namespace

void Dac3::reset() {
  // SVD: 0 everywhere but SHHR and SHRR 0x00010001.
  cr_ = dhr1_ = dhr2_ = dor1_ = dor2_ = sr_ = ccr_ = mcr_ = shsr1_ = shsr2_ = str1_ = str2_ = stmodr_ = 0;
  shhr_ = shrr_ = 0x00010001u;
  ready_at_[0] = ready_at_[1] = UINT64_MAX;
}

bool Dac3::output(int ch, double* volts) const {
  const unsigned en = ch == 1 ? 0u : 16u;
  if (!bit(cr_, en) || !bit(sr_, ch == 1 ? 11u : 27u)) return false;
  *volts = static_cast<double>(ch == 1 ? dor1_ : dor2_) * 3.3 / 4096.0;  // DAC output = VREF+ x DOR / 4096
  return true;
}

void Dac3::advance() {
  if (link_ == nullptr) return;
  const uint64_t now = link_->cycles();
  bool changed = false;
  for (int k = 0; k < 2; ++k) {
    if (ready_at_[k] <= now) {
      sr_ |= 1u << (k == 0 ? 11u : 27u);
      ready_at_[k] = UINT64_MAX;
      changed = true;
    }
  }
  if (changed && comps_ != nullptr) comps_->evaluate();
}

uint64_t Dac3::next_event() const { return std::min(ready_at_[0], ready_at_[1]); }

bool Dac3::read32(uint32_t off, uint32_t* v) {
  switch (off) {
    case DCR: *v = cr_; return true;
    case SWTRGR: *v = 0; return true;
    case DHR12R1: *v = dhr1_; return true;
    case DHR12L1: *v = dhr1_ << 4u; return true;
    case DHR8R1: *v = dhr1_ >> 4u; return true;
    case DHR12R2: *v = dhr2_; return true;
    case DHR12L2: *v = dhr2_ << 4u; return true;
    case DHR8R2: *v = dhr2_ >> 4u; return true;
    case DHR12RD: *v = dhr1_ | (dhr2_ << 16u); return true;
    case DHR12LD: *v = (dhr1_ << 4u) | (dhr2_ << 20u); return true;
    case DHR8RD: *v = (dhr1_ >> 4u) | ((dhr2_ >> 4u) << 8u); return true;
    case DOR1: *v = dor1_; return true;
    case DOR2: *v = dor2_; return true;
    case DSR: *v = sr_; return true;
    case DCCR: *v = ccr_; return true;
    case MCR: *v = mcr_; return true;
    case SHSR1: *v = shsr1_; return true;
    case SHSR2: *v = shsr2_; return true;
    case SHHR: *v = shhr_; return true;
    case SHRR: *v = shrr_; return true;
    case STR1: *v = str1_; return true;
    case STR2: *v = str2_; return true;
    case STMODR: *v = stmodr_; return true;
    default: return false;
  }
}

bool Dac3::write32(uint32_t off, uint32_t v) {
  // With TENx clear the holding register reaches DOR one bus clock later (RM0440 22.4.5): at once here.
  auto load = [this]() {
    if (!bit(cr_, 1u)) dor1_ = dhr1_;
    if (!bit(cr_, 17u)) dor2_ = dhr2_;
    if (comps_ != nullptr) comps_->evaluate();
  };
  switch (off) {
    case DCR: {
      const uint32_t old = cr_;
      cr_ = v;
      const uint64_t now = link_ ? link_->cycles() : 0u;
      const double hz = link_ ? static_cast<double>(link_->hclk_hz()) : 16e6;
      for (int k = 0; k < 2; ++k) {
        const unsigned en = k == 0 ? 0u : 16u;
        if (bit(cr_, en) && !bit(old, en)) {
          // RM0440 22.7.15 DAC_MCR HFSEL: 01 above 80 MHz of AHB clock, 10 above 160 MHz.
          const uint32_t hfsel = field(mcr_, 14u, 2u);
          const uint32_t need = hz > 160e6 ? 2u : (hz > 80e6 ? 1u : 0u);
          if (strict_hfsel_ && hfsel < need && link_) {
            link_->stop(name() + ": channel enabled at " + std::to_string(static_cast<unsigned>(hz / 1e6)) +
                        " MHz HCLK with DAC_MCR.HFSEL = " + std::to_string(hfsel) + " (RM0440 22.7.15: " +
                        std::to_string(need) + " needed)");
            return true;
          }
          ready_at_[k] = now + static_cast<uint64_t>(std::ceil(DAC_WAKEUP_S * hz));
        }
        if (!bit(cr_, en)) {
          sr_ &= ~(1u << (k == 0 ? 11u : 27u));
          ready_at_[k] = UINT64_MAX;
        }
      }
      load();
      if (comps_ != nullptr) comps_->evaluate();
      return true;
    }
    case SWTRGR:
      if (bit(v, 0u)) dor1_ = dhr1_;
      if (bit(v, 1u)) dor2_ = dhr2_;
      if (comps_ != nullptr) comps_->evaluate();
      return true;
    case DHR12R1: dhr1_ = v & 0xFFFu; load(); return true;
    case DHR12L1: dhr1_ = (v >> 4u) & 0xFFFu; load(); return true;
    case DHR8R1: dhr1_ = (v & 0xFFu) << 4u; load(); return true;
    case DHR12R2: dhr2_ = v & 0xFFFu; load(); return true;
    case DHR12L2: dhr2_ = (v >> 4u) & 0xFFFu; load(); return true;
    case DHR8R2: dhr2_ = (v & 0xFFu) << 4u; load(); return true;
    case DHR12RD: dhr1_ = v & 0xFFFu; dhr2_ = (v >> 16u) & 0xFFFu; load(); return true;
    case DHR12LD: dhr1_ = (v >> 4u) & 0xFFFu; dhr2_ = (v >> 20u) & 0xFFFu; load(); return true;
    case DHR8RD: dhr1_ = (v & 0xFFu) << 4u; dhr2_ = ((v >> 8u) & 0xFFu) << 4u; load(); return true;
    case DSR: sr_ &= ~(v & ((1u << 13u) | (1u << 29u))); return true;  // DMAUDR flags, rc_w1
    case DCCR: ccr_ = v; return true;
    case MCR:
      // MODEx is written only with ENx clear (RM0440 22.7.15).
      if ((bit(cr_, 0u) && field(v, 0u, 3u) != field(mcr_, 0u, 3u)) ||
          (bit(cr_, 16u) && field(v, 16u, 3u) != field(mcr_, 16u, 3u))) {
        if (link_) link_->stop(name() + ": DAC_MCR MODEx written with the channel enabled (RM0440 22.7.15)");
        return true;
      }
      mcr_ = v;
      return true;
    case SHSR1: shsr1_ = v; return true;
    case SHSR2: shsr2_ = v; return true;
    case SHHR: shhr_ = v; return true;
    case SHRR: shrr_ = v; return true;
    case STR1: str1_ = v; return true;
    case STR2: str2_ = v; return true;
    case STMODR: stmodr_ = v; return true;
    default: return false;  // DOR1/2 are read-only
  }
}

// ----------------------------------------------------------------------------------------------- COMP
void Comps::reset() {
  csr_.fill(0);  // SVD: COMP_CxCSR reset 0
  out_.fill(false);
}

void Comps::evaluate() {
  bool changed = false;
  for (int k = 0; k < 4; ++k) {
    const uint32_t c = csr_[static_cast<size_t>(k)];
    bool raw = false;
    if (bit(c, 0u) && plant_ != nullptr) {
      // INP (RM0440 24.3.2, table "COMPx non-inverting input"): INPSEL 0: COMP1 PA1, COMP2 PA7, COMP3 PA0,
      // COMP4 PB0; INPSEL 1: COMP1 PB1, COMP2 PA3, COMP3 PC1, COMP4 PE7.
      double inp = 0.0;
      if (!bit(c, 8u)) {
        inp = k == 2 ? plant_->vbus_pin() : plant_->shunt_vinp(k == 3 ? 2 : k);
      } else if (k == 0) {
        double v = 0.0;
        inp = (opamps_ != nullptr && opamps_->output(2, &v)) ? v : 0.0;  // PB1 = OPAMP3's output
      } else if (k == 1) {
        inp = plant_->vinm0(0);  // PA3 = OPAMP1's VINM0 pin
      }
      // INM (INMSEL): 000..011 VREFINT x 1/4, 1/2, 3/4, 1 (DS12589 VREFINT 1.212 V typ.); 100 DAC3 CH1
      // (COMP1, COMP3) / DAC3 CH2 (COMP2, COMP4); 101 DAC1 (not on this board's image); 110, 111 pins.
      double inm = 0.0;
      const uint32_t sel = field(c, 4u, 3u);
      const double vrefint = 1.212;
      switch (sel) {
        case 0: inm = vrefint / 4.0; break;
        case 1: inm = vrefint / 2.0; break;
        case 2: inm = vrefint * 3.0 / 4.0; break;
        case 3: inm = vrefint; break;
        case 4: {
          double v = 0.0;
          inm = (dac_ != nullptr && dac_->output((k == 0 || k == 2) ? 1 : 2, &v)) ? v : 0.0;
          break;
        }
        default:
          inm = 0.0;
          break;
      }
      // HYST: 0..7 x 10 mV; the output falls only once INP is below INM by the hysteresis.
      const double hyst = 0.010 * static_cast<double>(field(c, 16u, 3u));
      const bool was_raw = out_[static_cast<size_t>(k)] != bit(c, 15u);
      raw = was_raw ? (inp > inm - hyst) : (inp > inm);
    }
    const bool out = bit(c, 0u) && (raw != bit(c, 15u));  // POL inverts; a disabled comparator reads 0
    if (out != out_[static_cast<size_t>(k)]) changed = true;
    out_[static_cast<size_t>(k)] = out;
  }
  if (changed && tim1_ != nullptr) tim1_->break_inputs_changed();
}

bool Comps::read32(uint32_t off, uint32_t* v) {
  if (off > 0x0Cu) return false;  // COMP5..7 do not exist on the STM32G431
  evaluate();
  const size_t k = off / 4u;
  *v = (csr_[k] & ~(1u << 30u)) | (out_[k] ? 1u << 30u : 0u);  // VALUE, read-only
  return true;
}

bool Comps::write32(uint32_t off, uint32_t v) {
  if (off > 0x0Cu) return false;
  uint32_t& c = csr_[off / 4u];
  if (bit(c, 31u)) return true;  // LOCK
  c = v & ~(1u << 30u);
  evaluate();
  return true;
}

}  // namespace vb
