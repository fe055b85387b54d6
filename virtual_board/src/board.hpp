// SPDX-License-Identifier: MIT
#ifndef POUR_VIRTUAL_BOARD_BOARD_HPP
#define POUR_VIRTUAL_BOARD_BOARD_HPP

#include <unicorn/unicorn.h>

#include <array>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "models.hpp"
#include "peripheral.hpp"
#include "profile.hpp"

namespace vb {

struct Options {
  std::string elf;
  std::string interface;
  double seconds = 10.0;
  bool until_heartbeat = false;
  bool print_can = false;
  bool realtime = false;
  bool stop_on_reset = false;
  bool estop_open = false;
  int ecc_page = -1;
  unsigned cpi_milli = 1000;  // cycles per instruction x 1000 (docs/virtual-board.md: the CPI model)
  double stall_core_at_ms = -1.0, stall_core_ms = 0.0;
  bool profile = false;  // instructions per exception handler and per 1 kHz step (profile.hpp), printed at the end
};

class Board;
class Scs : public Peripheral {
 public:
  explicit Scs(Board* b) : Peripheral("SCS (SysTick, NVIC, SCB)", 0xE000E000u, 0x1000u), board_(b) {}
  bool read(uint32_t offset, unsigned width, uint32_t* value) override;
  bool write(uint32_t offset, unsigned width, uint32_t value) override;
  void reset() override {}

 private:
  Board* board_;
};

class Board : public BoardLink, public TimeSource {
 public:
  static constexpr int kIrqs = 102;  // STM32G431: IRQ 0 .. 101 (RM0440 table 97)
  explicit Board(const Options& o);
  ~Board() override;
  std::string load(const std::vector<uint8_t>& image_flash);
  std::string init();
  int run();
  // Models beyond the digital ones (vanalog's analog chain), added before init().
  void add_model(std::unique_ptr<Peripheral> m) { extra_.push_back(std::move(m)); }

  void set_irq(int irqn, bool level) override;
  uint64_t cycles() const override;
  uint32_t hclk_hz() const override { return hclk_; }
  void stop(const std::string& reason) override;
  void request_reset(const std::string& cause) override;
  uint64_t now_ps() const override;
  uint64_t cycles_until_ps(uint64_t t_ps) const override;

  uint64_t first_heartbeat_ps() const { return first_heartbeat_ps_; }
  uint64_t instructions() const { return insns_; }
  uint64_t exceptions_taken() const { return exceptions_taken_; }
  unsigned resets() const { return resets_; }
  uint64_t frames_tx() const { return frames_tx_; }
  double wall_s() const { return wall_s_; }
  const std::string& stopped() const { return stopped_; }
  Gpio& gpio(int port) { return port == 0 ? gpioa_ : port == 1 ? gpiob_ : gpioc_; }
  // The bus seen from the host's side without SocketCAN (virtual_board/src/rig.hpp): a frame into FDCAN1's
  // RX path as one from the bus arrives, and every frame the board puts on the bus.
  void receive_frame(const CanFrame& f) { fdcan_.receive(f); }
  void to_bus(const CanFrame& f);  // onto the SocketCAN bus when bridged (another node's frame: candump sees it)
  std::function<void(const CanFrame&)> on_tx;
  void finish() { finish_ = true; }  // the run ends normally after this slice (a host script's end)

 private:
  friend class Scs;
  struct MmioPage {
    Board* board;
    uint32_t base;
  };
  struct FlashData {
    FlashData(Flash* f, uint32_t b, Board* bd) : flash(f), base(b), board(bd) {}
    Flash* flash;
    uint32_t base;
    Board* board;
  };
  struct Gate {
    Peripheral* model;
    uint32_t enr, bit;
  };
  static void hook_block(uc_engine* uc, uint64_t address, uint32_t size, void* user);
  static void hook_intr(uc_engine* uc, uint32_t intno, void* user);
  static bool hook_unmapped(uc_engine* uc, uc_mem_type type, uint64_t address, int size, int64_t value, void* user);
  static uint64_t mmio_read(uc_engine* uc, uint64_t offset, unsigned size, void* user);
  static void mmio_write(uc_engine* uc, uint64_t offset, unsigned size, uint64_t value, void* user);
  static uint64_t data_read(uc_engine* uc, uint64_t offset, unsigned size, void* user);
  static void data_write(uc_engine* uc, uint64_t offset, unsigned size, uint64_t value, void* user);
  static uint64_t ccm_read(uc_engine* uc, uint64_t offset, unsigned size, void* user);
  static void ccm_write(uc_engine* uc, uint64_t offset, unsigned size, uint64_t value, void* user);
  bool access(uint32_t addr, unsigned size, bool write, uint32_t* v);
  void set_hclk(uint32_t h);
  void pend(int exc);
  int priority(int exc) const;
  bool enabled(int exc) const;
  int best_pending() const;
  int execution_priority();
  void take_exception(int exc);
  void exception_return(uint32_t exc_return);
  void core_reset(bool power_on);
  void systick_advance();
  uint64_t systick_next() const;
  std::string open_can();
  void bridge();

  Options opt_;
  uc_engine* uc_ = nullptr;
  std::array<uint8_t, 128 * 1024> flash_mem_{};
  std::array<uint8_t, 32 * 1024> sram_{};
  Scs scs_{this};
  Rcc rcc_;
  Pwr pwr_;
  Iwdg iwdg_;
  Flash flash_;
  Gpio gpioa_{"GPIOA", 0}, gpiob_{"GPIOB", 1}, gpioc_{"GPIOC", 2};
  Fdcan fdcan_;
  SramCan sramcan_;
  std::vector<std::unique_ptr<Peripheral>> extra_;
  std::unique_ptr<FlashData> flash_data_;
  std::vector<Peripheral*> models_;
  std::vector<Gate> gates_;
  std::vector<std::unique_ptr<MmioPage>> pages_;
  std::set<uint32_t> mapped_pages_;
  std::unordered_map<uint64_t, uint32_t> block_insns_;

  uint64_t insns_ = 0, slice_end_ = 0;
  uint64_t time_ps_ = 0, time_cycles_ = 0;
  uint32_t hclk_ = 16000000u;
  uint32_t pc_ = 0;
  bool idle_ = false, stall_ = false, stop_soon_ = false, check_irq_ = false, stalled_once_ = false;
  int intno_ = -1;
  std::string stopped_, reset_cause_;
  // NVIC, SCB, SysTick state
  bool pending_[16 + kIrqs] = {};
  bool irq_level_[kIrqs] = {};
  uint32_t iser_[4] = {};
  uint8_t ipr_[kIrqs + 2] = {};
  uint8_t shpr_[12] = {};
  std::vector<int> active_;
  uint32_t vtor_ = 0, prigroup_ = 0, scr_ = 0, ccr_ = 0x200u, cpacr_ = 0;
  uint32_t syst_csr_ = 0, syst_rvr_ = 0, syst_cvr_ = 0;
  bool syst_countflag_ = false;
  uint64_t syst_base_cycles_ = 0;
  int can_fd_ = -1;
  uint64_t first_heartbeat_ps_ = UINT64_MAX, exceptions_taken_ = 0, frames_tx_ = 0, idle_cycles_ = 0;
  unsigned resets_ = 0;
  double wall_s_ = 0;
  bool trace_ = false, finish_ = false;
  uint64_t iterations_ = 0;
  std::unique_ptr<Profiler> profiler_;  // --profile
};

}  // namespace vb

#endif
