// SPDX-License-Identifier: MIT
// The virtual B-G431B-ESC1's contract between the emulated core and its peripheral models.
// Every model is one Peripheral over one address window of the STM32G431's memory map (RM0440 table 4,
// base addresses from the stm32g4 crate's SVD). The board dispatches each load and store in a window to
// its model; a model answers false for an offset it does not cover, and the board then stops with the PC,
// the address and the model's name (never a silent zero).
#ifndef POUR_VIRTUAL_BOARD_PERIPHERAL_HPP
#define POUR_VIRTUAL_BOARD_PERIPHERAL_HPP

#include <cstdint>
#include <string>

namespace vb {

// What a model may ask of the board: interrupt lines into the NVIC, and the time base.
class BoardLink {
 public:
  virtual ~BoardLink() = default;
  // Level of an NVIC interrupt line (RM0440 table 97 position); the NVIC latches a rising level as pending.
  virtual void set_irq(int irqn, bool level) = 0;
  // The core clock's cycles since reset (HCLK: 16 MHz HSI until the clock switch, then the PLL's).
  virtual uint64_t cycles() const = 0;
  virtual uint32_t hclk_hz() const = 0;
  // A model stops the board on an access the manual forbids or a configuration it cannot run, naming it.
  virtual void stop(const std::string& reason) = 0;
  // A system reset (IWDG expiry, SYSRESETREQ): every model is reset at the end of the current slice.
  virtual void request_reset(const std::string& cause) = 0;
};

class Peripheral {
 public:
  Peripheral(std::string name, uint32_t base, uint32_t size) : name_(std::move(name)), base_(base), size_(size) {}
  virtual ~Peripheral() = default;
  const std::string& name() const { return name_; }
  uint32_t base() const { return base_; }
  uint32_t size() const { return size_; }

  // offset from base(); width 1, 2 or 4 bytes. false: not a register this model covers.
  virtual bool read(uint32_t offset, unsigned width, uint32_t* value) = 0;
  virtual bool write(uint32_t offset, unsigned width, uint32_t value) = 0;
  // Every register to its SVD reset value (power-on and system reset alike, unless the manual says otherwise).
  virtual void reset() = 0;
  // Time has reached link.cycles(): run counters, conversions, flags, and raise interrupt lines.
  virtual void advance() {}
  // The earliest cycle at which this model next changes something the firmware could see (a timer update,
  // a conversion's end); UINT64_MAX when none. The board runs the core no further than the minimum.
  virtual uint64_t next_event() const { return UINT64_MAX; }

  void attach(BoardLink* link) { link_ = link; }

 protected:
  BoardLink* link_ = nullptr;

 private:
  std::string name_;
  uint32_t base_;
  uint32_t size_;
};

}  // namespace vb

#endif
