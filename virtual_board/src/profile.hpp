// SPDX-License-Identifier: MIT
// Instruction counts of the image's exception handlers and of its 1 kHz step, nesting aware
// (pour_virtual_board --profile; docs/virtual-board.md, "Cycle counts"). The board calls the hooks: every
// basic block it counts, every exception entry and return, every reset. Handlers are named by the ELF's
// symbol at their vector; the step by the symbols it is looked up by (a name, or name.constprop.N ...).
#ifndef POUR_VIRTUAL_BOARD_PROFILE_HPP
#define POUR_VIRTUAL_BOARD_PROFILE_HPP

#include <unicorn/unicorn.h>

#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace vb {

class Profiler {
 public:
  // The FUNC symbols of the ELF at path and the thread-mode functions to time (each found by its name or a
  // GCC clone of it, name.*); "" or why not.
  std::string load(const std::string& elf_path, const std::vector<std::string>& functions);

  // n instructions of the block at address, run at exception nesting depth (0: thread mode).
  void block(uc_engine* uc, uint32_t address, uint32_t n, size_t depth);
  // Exception exc entered, its handler at handler; overhead: the entry's cycles the board counts.
  void exception_entry(int exc, uint32_t handler, uint32_t overhead);
  // The innermost exception returns; overhead: the return's cycles the board counts.
  void exception_return(uint32_t overhead);
  // A chip reset: whatever was open is dropped (not counted).
  void reset();

  // The figures, cycles from the CPI model (instructions x cpi_milli / 1000, plus the entry and return).
  void report(std::FILE* out, unsigned cpi_milli, uint32_t hclk_hz, double emulated_s) const;

 private:
  struct Exc {  // per exception number
    std::string handler;
    uint64_t entries = 0, self_sum = 0, self_max = 0, incl_max = 0, preempted = 0;
    uint32_t overhead = 0;  // entry + return cycles of one
  };
  struct Frame {  // an exception in progress
    int exc;
    uint64_t e0, nested;
    uint32_t entry_overhead;
  };
  struct Func {
    std::string name;
    uint64_t calls = 0, incl_sum = 0, incl_max = 0, excl_sum = 0, excl_max = 0, preempted = 0;
  };
  struct Call {  // a timed function in progress, thread mode
    size_t func;
    uint32_t ret, sp;
    uint64_t e0, isr0;
  };
  std::string symbol_at(uint32_t address) const;

  std::map<uint32_t, std::pair<uint32_t, std::string>> symbols_;  // start -> (size, name)
  std::map<uint32_t, size_t> entries_;                             // a timed function's start -> funcs_ index
  std::vector<Func> funcs_;
  std::map<int, Exc> excs_;
  std::vector<Frame> frames_;
  std::vector<Call> calls_;
  uint64_t executed_ = 0;  // instructions (and entry/return cycles) of the whole run, idle skips excluded
  uint64_t in_isr_ = 0;    // ... of them inside exceptions
};

}  // namespace vb

#endif
