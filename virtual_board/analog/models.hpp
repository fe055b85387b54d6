// SPDX-License-Identifier: MIT
// The virtual B-G431B-ESC1's analog and motor-side peripherals (issue 37): TIM1, ADC1/ADC2 and their common
// block, OPAMP1..3, COMP1..4, DAC3, TIM4 and LPTIM1, each one vb::Peripheral over its window of the memory map.
// Register offsets, bit positions and reset values: RM0440 rev 8 (register maps of sections 21 ADC, 22 DAC,
// 24 COMP, 25 OPAMP, 28 TIM1, 29 TIM2/3/4, 33 LPTIM), as the stm32g4 crate's SVD spells them.
// The models talk to each other and to the plant through AnalogNet (the board's analog nodes).
#ifndef POUR_VB_ANALOG_MODELS_HPP
#define POUR_VB_ANALOG_MODELS_HPP

#include <array>
#include <cstdint>
#include <string>

#include "peripheral.hpp"

namespace vb {

class Plant;
class Opamps;
class Dac3;
class Comps;

// RM0440 table 97: NVIC positions.
enum Irq : int {
  IRQ_ADC1_2 = 18,
  IRQ_TIM1_BRK = 24,
  IRQ_TIM1_UP = 25,
  IRQ_TIM1_TRG_COM = 26,
  IRQ_TIM1_CC = 27,
  IRQ_TIM4 = 30,
  IRQ_LPTIM1 = 49,
  IRQ_COMP1_2_3 = 64,
  IRQ_COMP4 = 65,
};

// A time base that survives the clock switch: seconds since reset, accumulated from HCLK cycles at the
// frequency that held while they ran (each model calls sync() before it reads the time).
class TimeBase {
 public:
  void reset() { last_cycles_ = 0; seconds_ = 0.0; }
  double sync(const BoardLink* link) {
    const uint64_t c = link->cycles();
    if (c > last_cycles_) {
      seconds_ += static_cast<double>(c - last_cycles_) / static_cast<double>(link->hclk_hz());
      last_cycles_ = c;
    }
    return seconds_;
  }

 private:
  uint64_t last_cycles_ = 0;
  double seconds_ = 0.0;
};

// One model's registers as 32-bit words: read32 / write32 by aligned offset; narrow accesses (access.hpp)
// merged here, once for every model.
class RegPeripheral : public Peripheral {
 public:
  RegPeripheral(std::string name, uint32_t base, uint32_t size, bool words_only)
      : Peripheral(std::move(name), base, size), words_only_(words_only) {}
  bool read(uint32_t offset, unsigned width, uint32_t* value) override;
  bool write(uint32_t offset, unsigned width, uint32_t value) override;

 protected:
  virtual bool read32(uint32_t off, uint32_t* v) = 0;
  virtual bool write32(uint32_t off, uint32_t v) = 0;
  // The word a narrow write merges into: the register as read, but for the write-to-clear and the
  // event-generation registers, whose other lanes must write their no-effect value.
  virtual uint32_t merge_base(uint32_t /*off*/, uint32_t current) const { return current; }

 private:
  bool words_only_;
};

// ---------------------------------------------------------------------------------------------------------
// TIM1 (advanced-control timer, RM0440 section 28). Base 0x40012C00.
class Tim1 : public RegPeripheral {
 public:
  Tim1() : RegPeripheral("TIM1", 0x40012C00u, 0x400u, false) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;

  void connect(Plant* plant, Comps* comps) { plant_ = plant; comps_ = comps; }
  // Listener of TRGO2's rising edges (the ADCs' injected trigger); called with the edge's cycle.
  using Trgo2Sink = void (*)(void* ctx, uint64_t cycle);
  void add_trgo2_sink(Trgo2Sink fn, void* ctx);
  // The break input from the comparators (level, active per BKP): evaluated with no software involved.
  void break_inputs_changed();

  // For the plant and the tests.
  uint32_t count() const;
  bool counting_up() const;
  bool outputs_enabled() const;  // MOE and the bridge's channels: the switches follow the compares
  bool moe() const { return (bdtr_ & (1u << 15)) != 0u; }
  double duty(int phase) const;  // high side's share of the period from the active CCRx
  uint32_t period_ticks() const;  // ticks of the timer clock per PWM period (centre-aligned: 2 x ARR)
  bool low_side_on(int phase) const;  // at this instant
  bool low_side_on_at(int phase, uint64_t cycle) const;
  uint32_t sr() const { return sr_; }
  uint32_t deadtime_ticks() const;
  uint64_t period_start_cycle() const { return start_ + static_cast<uint64_t>(periods_done_) * cycles_per_period(); }

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  uint32_t merge_base(uint32_t off, uint32_t current) const override;
  uint64_t cycles_per_period() const;
  uint64_t tick_cycles() const { return static_cast<uint64_t>(psc_active_) + 1u; }
  void update_event(bool software);
  void do_break();
  void schedule();
  bool centre_aligned() const;
  uint64_t pos_ticks_at(uint64_t cycle) const;
  uint32_t count_at(uint64_t cycle) const;
  bool ref_at(int ch, uint64_t cycle) const;
  void raise_irqs();
  uint64_t pos_ticks() const;  // ticks into the current period

  Plant* plant_ = nullptr;
  Comps* comps_ = nullptr;
  std::array<Trgo2Sink, 4> sinks_{};
  std::array<void*, 4> sink_ctx_{};
  int nsinks_ = 0;

  uint32_t cr1_ = 0, cr2_ = 0, smcr_ = 0, dier_ = 0, sr_ = 0, ccmr1_ = 0, ccmr2_ = 0, ccmr3_ = 0, ccer_ = 0;
  uint32_t psc_ = 0, arr_ = 0xFFFFu, rcr_ = 0, bdtr_ = 0, dtr2_ = 0, ecr_ = 0, tisel_ = 0, af1_ = 0, af2_ = 0;
  uint32_t or1_ = 0, dcr_ = 0;
  std::array<uint32_t, 6> ccr_{};         // preload registers
  std::array<uint32_t, 6> ccr_active_{};  // shadows
  uint32_t arr_active_ = 0xFFFFu, psc_active_ = 0, rcr_active_ = 0;
  bool running_ = false;
  uint64_t start_ = 0;          // cycle at which the counter was at 0 counting up
  uint64_t periods_done_ = 0;   // whole periods since start_ (plant steps taken)
  uint64_t next_trgo2_ = UINT64_MAX;
  uint32_t cnt_stopped_ = 0;    // CNT while the counter is disabled
  uint32_t rep_ = 0;            // repetition down-counter
  uint64_t next_half_ = UINT64_MAX;
  bool break_active_ = false;
};

// ---------------------------------------------------------------------------------------------------------
// ADC1, ADC2 (RM0440 section 21) and their common registers ADC12_COMMON (base 0x50000300).
class Adc12Common : public RegPeripheral {
 public:
  Adc12Common() : RegPeripheral("ADC12_COMMON", 0x50000300u, 0x100u, true) {}
  void reset() override { ccr_ = 0; }
  // HCLK cycles per ADC clock cycle; 0 when CKMODE selects the asynchronous clock (not modelled).
  uint32_t hclk_per_adc_clock() const;
  uint32_t ccr() const { return ccr_; }

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  uint32_t ccr_ = 0;
};

class Adc : public RegPeripheral {
 public:
  Adc(int index, uint32_t base) : RegPeripheral(index == 1 ? "ADC1" : "ADC2", base, 0x100u, true), index_(index) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;

  void connect(Adc12Common* common, Plant* plant, Adc* partner) { common_ = common; plant_ = plant; partner_ = partner; }
  void trigger(uint64_t cycle);  // TIM1 TRGO2 rising edge
  uint32_t isr() const { return isr_; }
  uint32_t cr() const { return cr_; }
  uint32_t jdr(int rank) const { return jdr_[static_cast<size_t>(rank)]; }
  bool irq_level() const { return (isr_ & ier_ & 0x7FFu) != 0u; }
  bool regulator_ready() const;
  // Conversion time of one channel in HCLK cycles (sampling time from SMPRx + 12.5 ADC clocks, 12 bits).
  uint64_t conversion_cycles(uint32_t channel) const;

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  void update_irq();
  uint32_t sample(uint32_t channel);
  uint32_t sample_at(uint32_t channel, uint64_t cycle);

  int index_;
  Adc12Common* common_ = nullptr;
  Plant* plant_ = nullptr;
  Adc* partner_ = nullptr;
  TimeBase time_;
  uint32_t isr_ = 0, ier_ = 0, cr_ = 0x20000000u, cfgr_ = 0x80000000u, cfgr2_ = 0, smpr1_ = 0, smpr2_ = 0;
  uint32_t tr1_ = 0x0FFF0000u, tr2_ = 0x00FF0000u, tr3_ = 0x00FF0000u, sqr_[4] = {0, 0, 0, 0}, dr_ = 0;
  uint32_t jsqr_ = 0, ofr_[4] = {0, 0, 0, 0}, awd2cr_ = 0, awd3cr_ = 0, difsel_ = 0, calfact_ = 0, gcomp_ = 0;
  uint32_t jdr_[4] = {0, 0, 0, 0};
  double regulator_on_s_ = -1.0;  // time ADVREGEN was set; <0: off
  uint64_t cal_done_ = UINT64_MAX, ready_at_ = UINT64_MAX;
  bool ready_ = false;  // ADRDY has come since ADEN
  // The injected sequence in flight: each rank's end-of-conversion cycle.
  uint32_t seq_jsqr_ = 0;
  int seq_len_ = 0, seq_next_ = 0;
  uint64_t seq_end_[4] = {0, 0, 0, 0};
  uint32_t seq_code_[4] = {0, 0, 0, 0};
};

// ---------------------------------------------------------------------------------------------------------
// OPAMP1..3 (RM0440 section 25), base 0x40010300.
class Opamps : public RegPeripheral {
 public:
  Opamps() : RegPeripheral("OPAMP", 0x40010300u, 0x100u, false) {}  // RM0440 table 4: 0x4001 0300 .. 03FF
  void reset() override;
  void connect(Plant* plant) { plant_ = plant; }
  // The output pin's voltage of OPAMPk (k = 0..2); false when the op-amp is disabled (nothing drives the pin).
  bool output(int k, double* volts) const;
  uint32_t csr(int k) const { return csr_[static_cast<size_t>(k)]; }

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  Plant* plant_ = nullptr;
  std::array<uint32_t, 3> csr_{}, tcmr_{};
};

// ---------------------------------------------------------------------------------------------------------
// DAC3 (RM0440 section 22), base 0x50001000: internal channels only (the comparators' thresholds).
class Dac3 : public RegPeripheral {
 public:
  Dac3() : RegPeripheral("DAC3", 0x50001000u, 0x400u, false) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;
  void connect(Comps* comps, bool strict_hfsel) { comps_ = comps; strict_hfsel_ = strict_hfsel; }
  // Channel ch (1, 2) output voltage; false when the channel is off or not yet awake.
  bool output(int ch, double* volts) const;
  uint32_t mcr() const { return mcr_; }

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  Comps* comps_ = nullptr;
  bool strict_hfsel_ = false;
  uint32_t cr_ = 0, dhr1_ = 0, dhr2_ = 0, dor1_ = 0, dor2_ = 0, sr_ = 0, ccr_ = 0, mcr_ = 0;
  uint32_t shsr1_ = 0, shsr2_ = 0, shhr_ = 0x00010001u, shrr_ = 0x00010001u, str1_ = 0, str2_ = 0, stmodr_ = 0;
  uint64_t ready_at_[2] = {UINT64_MAX, UINT64_MAX};
};

// ---------------------------------------------------------------------------------------------------------
// COMP1..4 (RM0440 section 24), base 0x40010200; outputs into TIM1's break (TIM1_AF1 BKCMPxE).
class Comps : public RegPeripheral {
 public:
  Comps() : RegPeripheral("COMP", 0x40010200u, 0x100u, false) {}  // RM0440 table 4: 0x4001 0200 .. 02FF
  void reset() override;
  void connect(Plant* plant, Dac3* dac, Tim1* tim1, Opamps* opamps) { plant_ = plant; dac_ = dac; tim1_ = tim1; opamps_ = opamps; }
  // Re-evaluate every comparator (inputs moved); tells TIM1 when an output changed.
  void evaluate();
  bool output(int k) const { return out_[static_cast<size_t>(k)]; }  // k = 0..3 for COMP1..4, after POL

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  Plant* plant_ = nullptr;
  Dac3* dac_ = nullptr;
  Tim1* tim1_ = nullptr;
  Opamps* opamps_ = nullptr;
  std::array<uint32_t, 4> csr_{};
  std::array<bool, 4> out_{};
};

// ---------------------------------------------------------------------------------------------------------
// TIM4 (general-purpose timer, RM0440 section 29), base 0x40000800, as the encoder's counter.
class Tim4 : public RegPeripheral {
 public:
  Tim4() : RegPeripheral("TIM4", 0x40000800u, 0x400u, false) {}
  void reset() override;
  // The plant's quadrature edges since the last call (x4: every edge of A and B; sign: A leads B = up).
  void edges(int64_t x4_edges);
  uint32_t cnt() const { return cnt_; }

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  uint32_t merge_base(uint32_t off, uint32_t current) const override;
  void count(int64_t n);
  uint32_t cr1_ = 0, cr2_ = 0, smcr_ = 0, dier_ = 0, sr_ = 0, ccmr1_ = 0, ccmr2_ = 0, ccer_ = 0, cnt_ = 0;
  uint32_t psc_ = 0, arr_ = 0xFFFFFFFFu, ccr_[4] = {0, 0, 0, 0}, ecr_ = 0, tisel_ = 0, af1_ = 0, af2_ = 0, dcr_ = 0;
  int64_t half_ = 0;  // x2 modes: an odd edge waiting for its pair
};

// ---------------------------------------------------------------------------------------------------------
// LPTIM1 (RM0440 section 33), base 0x40007C00: the clock check's independent counter.
class Lptim1 : public RegPeripheral {
 public:
  explicit Lptim1(double kernel_hz) : RegPeripheral("LPTIM1", 0x40007C00u, 0x400u, true), kernel_hz_(kernel_hz) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;

 private:
  bool read32(uint32_t off, uint32_t* v) override;
  bool write32(uint32_t off, uint32_t v) override;
  uint32_t count_now();
  double kernel_hz_;
  TimeBase time_;
  uint32_t isr_ = 0, ier_ = 0, cfgr_ = 0, cr_ = 0, cmp_ = 0, arr_ = 1u, or_ = 0;
  bool counting_ = false;
  double count_origin_s_ = 0.0;  // time at which the count was 0
  double arrok_at_s_ = -1.0, cmpok_at_s_ = -1.0;
  uint64_t arrok_cycle_ = UINT64_MAX;
};

}  // namespace vb

#endif
