// SPDX-License-Identifier: MIT
// The digital models of the virtual B-G431B-ESC1: register files initialised from ST's SVD (the stm32g4
// crate, virtual_board/gen_svd_map.py) and the behaviour RM0440 gives each block the image uses.
#ifndef POUR_VIRTUAL_BOARD_MODELS_HPP
#define POUR_VIRTUAL_BOARD_MODELS_HPP

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "peripheral.hpp"

namespace vb {

struct SvdPeriph {
  const char* name;
  uint32_t base;
};
struct SvdReg {
  const char* periph;
  const char* name;
  uint32_t offset;
  uint32_t width;
  uint32_t reset;
};
const std::vector<SvdPeriph>& svd_periphs();
const std::vector<SvdReg>& svd_regs();
// The SVD peripheral whose 1 KB window holds addr (RM0440 table 4's granularity), or "" if none.
std::string svd_name_at(uint32_t addr);
uint32_t svd_base(const std::string& svd_name);

// A model whose registers are the SVD's for its peripheral: each starts at its reset value; an offset the
// SVD does not list is not covered.
class SvdRegisters : public Peripheral {
 public:
  SvdRegisters(const std::string& svd_name, const std::string& name, uint32_t size);
  bool read(uint32_t offset, unsigned width, uint32_t* value) override;
  bool write(uint32_t offset, unsigned width, uint32_t value) override;
  void reset() override;

 protected:
  // Hooks for the registers with behaviour; the default is a plain store.
  virtual uint32_t on_read(uint32_t offset, uint32_t stored) { (void)offset; return stored; }
  virtual void on_write(uint32_t offset, uint32_t old, uint32_t* value) { (void)offset; (void)old; (void)value; }
  uint32_t& reg(uint32_t offset) { return regs_.at(offset); }
  std::map<uint32_t, uint32_t> regs_;
  std::map<uint32_t, uint32_t> resets_;
};

// The board's time in picoseconds (the models' common clock across HCLK changes).
class TimeSource {
 public:
  virtual ~TimeSource() = default;
  virtual uint64_t now_ps() const = 0;
  virtual uint64_t cycles_until_ps(uint64_t t_ps) const = 0;
};

class Rcc;
class Pwr : public SvdRegisters {
 public:
  Pwr() : SvdRegisters("PWR", "PWR", 0x400) {}
  bool boost() { return (reg(0x80) & (1u << 8)) == 0u; }  // CR5.R1MODE = 0: range 1 boost (RM0440 §6.1.5)
};

class Flash;
class Rcc : public SvdRegisters {
 public:
  Rcc(TimeSource* t) : SvdRegisters("RCC", "RCC", 0x400), t_(t) {}
  void reset() override;
  uint32_t hclk_hz();
  void advance() override;
  uint64_t next_event() const override;
  void note_reset(uint32_t csr_flags) { csr_flags_ = csr_flags; }
  bool enabled(uint32_t enr_offset, uint32_t bit) { return (reg(enr_offset) & (1u << bit)) != 0u; }
  Flash* flash = nullptr;
  Pwr* pwr = nullptr;

 protected:
  uint32_t on_read(uint32_t offset, uint32_t stored) override;
  void on_write(uint32_t offset, uint32_t old, uint32_t* value) override;

 private:
  bool ready(unsigned which) const;
  TimeSource* t_;
  uint64_t hse_on_ps_ = UINT64_MAX, pll_on_ps_ = UINT64_MAX;
  uint32_t csr_flags_ = (1u << 26) | (1u << 27);  // PINRSTF, BORRSTF: a power-on (RM0440 RCC_CSR)
  uint32_t sws_ = 1u;                              // HSI16 after reset
};

class Iwdg : public SvdRegisters {
 public:
  Iwdg(TimeSource* t) : SvdRegisters("IWDG", "IWDG", 0x400), t_(t) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;
  // The timeout of the count running: the reload value and prescaler in the counter's (LSI) domain when the
  // counter was last reloaded (RM0440 §41.3.2: a key 0xAAAA reloads IWDG_RLR's value into the counter; a new
  // RLR or PR reaches that domain only after RVU / PVU clear, 5 LSI periods, and the count under way keeps
  // the value it was loaded with). A PR change is taken at the next reload (the image writes one value).
  uint64_t timeout_ps() const { return loaded_ps_; }
  bool running() const { return running_; }
  uint64_t expiry_ps() const { return running_ ? reload_ps_ + loaded_ps_ : UINT64_MAX; }
  uint32_t lsi_hz = 32000u;  // datasheet LSI typical 32 kHz (29.5 .. 34 kHz: board_facts.h LSI_MAX_HZ)

 protected:
  uint32_t on_read(uint32_t offset, uint32_t stored) override;
  void on_write(uint32_t offset, uint32_t old, uint32_t* value) override;

 private:
  TimeSource* t_;
  void settle();   // RLR / PR into the counter's domain once RVU / PVU have cleared
  void reload(bool start);  // the counter loaded: 0xFFF at the start, else the domain's RLR
  bool running_ = false, unlocked_ = false;
  uint64_t reload_ps_ = 0, busy_until_ps_ = 0, loaded_ps_ = 0;
  uint32_t domain_pr_ = 0, domain_rl_ = 0xFFFu;  // the reset values (RM0440 §41.4.2, §41.4.3)
};

// FLASH interface (RM0440 §3.7) and the two data pages at the end of the 128 KB (62, 63), which are
// mapped through it so that programming, erase and ECC follow the manual.
class Flash : public SvdRegisters {
 public:
  Flash(TimeSource* t, uint8_t* flash_bytes, uint32_t flash_size)
      : SvdRegisters("FLASH", "FLASH", 0x400), t_(t), mem_(flash_bytes), size_(flash_size) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;
  uint32_t latency() { return reg(0x00) & 0xFu; }
  // Data-page access (address offset from 0x08000000); false if refused (stops the board).
  bool data_read(uint32_t offset, unsigned width, uint32_t* value);
  bool data_write(uint32_t offset, unsigned width, uint32_t value);
  int ecc_page = -1;                    // a page left half-erased: a read of it is a double ECC error
  uint64_t erase_ps = 24470000000ull;   // board_facts.h FLASH_PAGE_ERASE_MAX_US (datasheet tERASE max)
  uint64_t program_ps = 90000000ull;    // datasheet tPROG 64-bit: 81.7 .. 90.8 us
  uint64_t stall_until_ps = 0;          // the core stalls on a fetch while an erase runs (one bank)
  bool nmi_pending = false;

 protected:
  uint32_t on_read(uint32_t offset, uint32_t stored) override;
  void on_write(uint32_t offset, uint32_t old, uint32_t* value) override;

 private:
  TimeSource* t_;
  uint8_t* mem_;
  uint32_t size_;
  int key_state_ = 0;
  uint64_t busy_until_ps_ = 0;
  bool pending_low_ = false;
  uint32_t low_word_ = 0, low_offset_ = 0;
};

// A GPIO port (RM0440 §9) and what is wired to its pins outside the chip.
class Gpio : public SvdRegisters {
 public:
  Gpio(const std::string& svd_name, int port) : SvdRegisters(svd_name, svd_name, 0x400), port_(port) {}
  // External level on a pin when the chip does not drive it: -1 none (the chip's pull decides), 0, 1.
  std::vector<int> external = std::vector<int>(16, -1);
  bool driven_high(unsigned pin);
  bool is_output(unsigned pin) { return ((reg(0x00) >> (2u * pin)) & 3u) == 1u; }
  int port() const { return port_; }

 protected:
  uint32_t on_read(uint32_t offset, uint32_t stored) override;
  void on_write(uint32_t offset, uint32_t old, uint32_t* value) override;

 private:
  int port_;
};

struct CanFrame {
  uint32_t id;
  uint8_t dlc;
  uint8_t data[8];
};

// FDCAN1 (RM0440 §44) with its message RAM (SRAMCAN, 0x350 bytes at 0x4000A400, fixed layout: 28 standard
// filters, 8 extended, RX FIFO 0 and 1 of 3 elements, TX event FIFO, 3 TX buffers).
class Fdcan : public SvdRegisters {
 public:
  Fdcan(TimeSource* t) : SvdRegisters("FDCAN1", "FDCAN1", 0x400), t_(t) {}
  void reset() override;
  void advance() override;
  uint64_t next_event() const override;
  void receive(const CanFrame& f);  // a frame from the bus
  std::deque<CanFrame> transmitted;  // frames put on the bus, for the bridge
  uint32_t ram[0x350 / 4] = {};

 protected:
  uint32_t on_read(uint32_t offset, uint32_t stored) override;
  void on_write(uint32_t offset, uint32_t old, uint32_t* value) override;

 private:
  uint64_t bit_ps() const;
  TimeSource* t_;
  uint32_t rx_get_ = 0, rx_fill_ = 0;
  uint32_t tx_get_ = 0, tx_fill_ = 0;
  uint32_t tx_pending_ = 0;
  uint64_t tx_done_ps_ = UINT64_MAX;
};

class SramCan : public Peripheral {
 public:
  explicit SramCan(Fdcan* can) : Peripheral("SRAMCAN", 0x4000A400u, 0x400), can_(can) {}
  bool read(uint32_t offset, unsigned width, uint32_t* value) override;
  bool write(uint32_t offset, unsigned width, uint32_t value) override;
  void reset() override {}  // the message RAM is not reset with the peripheral (RM0440 §44.3.3)

 private:
  Fdcan* can_;
};

}  // namespace vb

#endif
