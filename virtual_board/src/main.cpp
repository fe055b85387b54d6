// SPDX-License-Identifier: MIT
// pour_virtual_board: the flashed pour_firmware.elf on an emulated STM32G431 (docs/virtual-board.md).
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "analog.hpp"
#include "board.hpp"
#include "rig.hpp"

namespace {

// The analog chain's plant, stepped by the board as one more model: it covers no address, and its next event
// is the next PWM period's start (virtual_board/analog/analog.hpp). A reset of the chip does not reset it:
// the motor, its rotor's angle and speed, the bus capacitor's charge and the bucket on the gear are outside
// the MCU (TIM4's count restarts at 0 with TIM1's outputs off, as their models' resets have it).
class PlantStep : public vb::Peripheral {
 public:
  explicit PlantStep(vb::Plant* p) : Peripheral("plant", 0, 0), plant_(p) {}
  bool read(uint32_t, unsigned, uint32_t*) override { return false; }
  bool write(uint32_t, unsigned, uint32_t) override { return false; }
  void reset() override {}
  void advance() override { plant_->step_to_cycle(link_); }
  uint64_t next_event() const override { return plant_->next_step_cycle(link_); }

 private:
  vb::Plant* plant_;
};

const char* kUsage =
    "usage: pour_virtual_board [--elf FILE] [--channel CHANNEL [--interface socketcan]] [--seconds S] [--until-heartbeat]\n"
    "                          [--print-can]\n"
    "                          [--realtime] [--estop open|closed] [--ecc-page N] [--stall-core-at MS --stall-core-ms MS]\n"
    "                          [--stop-on-reset] [--cpi-milli N] [--bench] [--profile]\n"
    "                          [--world | --empty-rig | --pour [--reset-before-pour]] [--seed N]\n"
    "                          [--estop-at MS] [--overcurrent-at MS [--overcurrent-a A]]\n"
    "                          [--episode-s S] [--hold-s S] [--csv FILE] [--brake-ms MS] [--gear-stiffness K]\n"
    "                          [--read-calibration] [--clear-at MS] [--fill-at MS] [--corrupt-page N]\n"
    "Runs the STM32G431 image (default build/cortex-m4/firmware/ports/cortex-m4/pour_firmware.elf) on the virtual\n"
    "B-G431B-ESC1. Exit 0 at the end of the run, 1 if the board stopped (an unmapped access, a register no model\n"
    "covers, a configuration the manual forbids), 2 on bad input.\n"
    "  --world         host_sim's bucket world (seed --seed) behind the gear from power-on: the rig's Sensors frame\n"
    "                  into FDCAN1 every 1 ms physics step, the holding brake on PB3\n"
    "  --seed N        the world's (the liquid, the scales' noise) and the converters' noise (default 1)\n"
    "  --empty-rig     the same with the rotating bucket empty (the bench's calibration: pour-bench calibrate)\n"
    "  --pour          the bench's script, in emulated time (docs/virtual-board.md): the empty rig, CalibrationStart,\n"
    "                  the outcome, the bucket filled (held by the brake), ClearErrors, the pour, Stop after\n"
    "                  --episode-s (10) of RUN, --hold-s (1.5) more, a reset and CalibrationRead; prints R, L, poured,\n"
    "                  spilled, theta. --reset-before-pour: the reset and the read-back before the pour instead.\n"
    "                  Exit 1 if a step fails (the reason on stderr)\n"
    "  --gear-stiffness K  the gear's spring at the output [N m/rad] (default 2000, assumed), its damping scaled\n"
    "  --brake-ms MS   the brake holds MS after PB3 falls (default 20, assumed); released at once\n"
    "  --csv FILE      with --pour: the world's every step from RUN on (host_sim --csv's columns)\n"
    "  --read-calibration  with --world or --empty-rig: CalibrationRead 50 ms after the first heartbeat\n"
    "  --clear-at MS       with --world or --empty-rig: ClearErrors at MS emulated\n"
    "  --fill-at MS        with --empty-rig: the bucket filled at MS (once the brake holds): host_sim's world\n"
    "  --corrupt-page N    page 62 or 63 starts with a double-word of zeros (a write cut short)\n"
    "  --estop-at MS   the e-stop contact opens at MS emulated; --overcurrent-at MS: --overcurrent-a A (-50: out of\n"
    "                  the phase, through its shunt) added to phase U's current from MS on\n";

int bad(const std::string& msg) {
  std::fprintf(stderr, "pour_virtual_board: %s\n", msg.c_str());
  return 2;
}

uint32_t u32(const std::vector<uint8_t>& b, size_t o) {
  return uint32_t{b[o]} | uint32_t{b[o + 1]} << 8 | uint32_t{b[o + 2]} << 16 | uint32_t{b[o + 3]} << 24;
}
uint16_t u16(const std::vector<uint8_t>& b, size_t o) { return static_cast<uint16_t>(b[o] | b[o + 1] << 8); }

// SHA-256 (FIPS 180-4), to print the image's hash as scripts/flash.sh's sha256sum would.
std::string sha256(const std::vector<uint8_t>& data) {
  static const uint32_t k[64] = {
      0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5, 0xd807aa98, 0x12835b01,
      0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc,
      0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147,
      0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
      0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116, 0x1e376c08,
      0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208,
      0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};
  uint32_t h[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::vector<uint8_t> m(data);
  const uint64_t bits = static_cast<uint64_t>(data.size()) * 8u;
  m.push_back(0x80);
  while (m.size() % 64 != 56) m.push_back(0);
  for (int i = 7; i >= 0; --i) m.push_back(static_cast<uint8_t>(bits >> (8 * i)));
  auto rotr = [](uint32_t x, int n) { return (x >> n) | (x << (32 - n)); };
  for (size_t c = 0; c < m.size(); c += 64) {
    uint32_t w[64];
    for (size_t i = 0; i < 16; ++i) w[i] = (uint32_t)m[c + 4 * i] << 24 | (uint32_t)m[c + 4 * i + 1] << 16 | (uint32_t)m[c + 4 * i + 2] << 8 | m[c + 4 * i + 3];
    for (int i = 16; i < 64; ++i) {
      const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    uint32_t a = h[0], b = h[1], cc = h[2], d = h[3], e = h[4], f = h[5], g = h[6], hh = h[7];
    for (int i = 0; i < 64; ++i) {
      const uint32_t t1 = hh + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + k[i] + w[i];
      const uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & cc) ^ (b & cc));
      hh = g; g = f; f = e; e = d + t1; d = cc; cc = b; b = a; a = t1 + t2;
    }
    h[0] += a; h[1] += b; h[2] += cc; h[3] += d; h[4] += e; h[5] += f; h[6] += g; h[7] += hh;
  }
  char out[65];
  for (int i = 0; i < 8; ++i) std::snprintf(out + 8 * i, 9, "%08x", h[i]);
  return out;
}

// The image's PT_LOAD segments at their load (physical) addresses into the 128 KB flash; "" or why not.
std::string load_elf(const std::string& path, const std::vector<uint8_t>& b, std::vector<uint8_t>* flash) {
  const std::string who = path + ": not the STM32G431 image: ";
  if (b.size() < 52 || std::memcmp(b.data(), "\x7f" "ELF", 4) != 0) return who + "not an ELF file";
  if (b[4] != 1 || b[5] != 1) return who + "not a 32-bit little-endian ELF";
  if (u16(b, 18) != 40) return who + "not an ARM ELF (e_machine " + std::to_string(u16(b, 18)) + ")";
  const uint32_t phoff = u32(b, 28);
  const uint16_t phentsize = u16(b, 42), phnum = u16(b, 44);
  if (phnum == 0 || phoff + static_cast<uint64_t>(phentsize) * phnum > b.size()) return who + "no program headers";
  flash->assign(128 * 1024, 0xFF);
  bool at_vectors = false;
  for (uint16_t i = 0; i < phnum; ++i) {
    const size_t ph = phoff + static_cast<size_t>(i) * phentsize;
    if (u32(b, ph) != 1u) continue;  // PT_LOAD
    const uint32_t off = u32(b, ph + 4), paddr = u32(b, ph + 12), filesz = u32(b, ph + 16);
    if (filesz == 0) continue;
    if (paddr < 0x08000000u || paddr + static_cast<uint64_t>(filesz) > 0x08020000u) {
      char m[96];
      std::snprintf(m, sizeof m, "a segment loads at 0x%08x, outside the 128 KB flash at 0x08000000", paddr);
      return who + m;
    }
    if (off + static_cast<uint64_t>(filesz) > b.size()) return who + "a segment runs past the file's end";
    std::memcpy(flash->data() + (paddr - 0x08000000u), b.data() + off, filesz);
    if (paddr == 0x08000000u) at_vectors = true;
  }
  if (!at_vectors) return who + "no vector table at 0x08000000";
  const uint32_t sp = u32(*flash, 0), reset = u32(*flash, 4);
  if (sp < 0x20000000u || sp > 0x20008000u) return who + "the initial stack pointer is outside SRAM";
  if (!(reset & 1u) || reset < 0x08000000u || reset >= 0x08020000u) return who + "the reset vector is not a Thumb address in flash";
  // The bytes loaded are the segments' bytes: checked back, segment by segment.
  for (uint16_t i = 0; i < phnum; ++i) {
    const size_t ph = phoff + static_cast<size_t>(i) * phentsize;
    if (u32(b, ph) != 1u || u32(b, ph + 16) == 0) continue;
    if (std::memcmp(flash->data() + (u32(b, ph + 12) - 0x08000000u), b.data() + u32(b, ph + 4), u32(b, ph + 16)) != 0) {
      return who + "the loaded bytes differ from a PT_LOAD segment";
    }
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  vb::Options o;
  o.elf = "build/cortex-m4/firmware/ports/cortex-m4/pour_firmware.elf";
  bool bench = false, seconds_given = false;
  vb::RigOptions rig;
  vb::AnalogOptions ao;
  double overcurrent_at_ms = -1.0;
  int corrupt_page = -1;
  ao.fault_phase_overcurrent_a = 0.0;
  double overcurrent_a = -50.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) return nullptr;
      (void)name;
      return argv[++i];
    };
    const char* v = nullptr;
    try {
      if (a == "--help" || a == "-h") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (a == "--elf") {
        if (!(v = value("--elf"))) return bad("--elf needs a file");
        o.elf = v;
      } else if (a == "--channel") {  // python-can's and pour-bench's names: the channel is vcan0, can0
        if (!(v = value("--channel"))) return bad("--channel needs a SocketCAN interface name (vcan0)");
        o.interface = v;
        o.realtime = true;
      } else if (a == "--interface") {
        if (!(v = value("--interface"))) return bad("--interface needs a backend (socketcan)");
        if (std::string(v) != "socketcan") return bad("--interface '" + std::string(v) + "': only socketcan is supported");
      } else if (a == "--iface") {
        return bad("--iface is now --channel (python-can's name): --channel vcan0");
      } else if (a == "--seconds") {
        if (!(v = value("--seconds"))) return bad("--seconds needs a number");
        o.seconds = std::stod(v);
        if (!(o.seconds > 0 && o.seconds < 1e6)) return bad("--seconds must be in (0, 1e6)");
        seconds_given = true;
      } else if (a == "--until-heartbeat") o.until_heartbeat = true;
      else if (a == "--print-can") o.print_can = true;
      else if (a == "--realtime") o.realtime = true;
      else if (a == "--stop-on-reset") o.stop_on_reset = true;
      else if (a == "--bench") bench = true;
      else if (a == "--profile") o.profile = true;  // virtual_board/src/profile.hpp
      else if (a == "--estop") {
        if (!(v = value("--estop"))) return bad("--estop needs open or closed");
        if (std::string(v) != "open" && std::string(v) != "closed") return bad("--estop must be open or closed");
        o.estop_open = std::string(v) == "open";
      } else if (a == "--ecc-page") {
        if (!(v = value("--ecc-page"))) return bad("--ecc-page needs a page number");
        o.ecc_page = std::stoi(v);
        if (o.ecc_page < 62 || o.ecc_page > 63) return bad("--ecc-page must be 62 or 63 (the data pages)");
      } else if (a == "--cpi-milli") {
        if (!(v = value("--cpi-milli"))) return bad("--cpi-milli needs a number");
        const int c = std::stoi(v);
        if (c < 500 || c > 4000) return bad("--cpi-milli must be in 500 .. 4000");
        o.cpi_milli = static_cast<unsigned>(c);
      } else if (a == "--stall-core-at") {
        if (!(v = value(a.c_str()))) return bad("--stall-core-at needs milliseconds");
        o.stall_core_at_ms = std::stod(v);
      } else if (a == "--stall-core-ms") {
        if (!(v = value(a.c_str()))) return bad("--stall-core-ms needs milliseconds");
        o.stall_core_ms = std::stod(v);
        if (!(o.stall_core_ms > 0)) return bad("--stall-core-ms must be positive");
      } else if (a == "--world") rig.world = true;
      else if (a == "--empty-rig") rig.empty = true;
      else if (a == "--read-calibration") rig.read_calibration = true;
      else if (a == "--fill-at") {
        if (!(v = value(a.c_str()))) return bad("--fill-at needs milliseconds");
        rig.fill_at_ms = std::stod(v);
        if (!(rig.fill_at_ms >= 0 && rig.fill_at_ms < 1e9)) return bad("--fill-at must be in 0 .. 1e9 ms");
      } else if (a == "--clear-at") {
        if (!(v = value(a.c_str()))) return bad("--clear-at needs milliseconds");
        rig.clear_at_ms = std::stod(v);
        if (!(rig.clear_at_ms >= 0 && rig.clear_at_ms < 1e9)) return bad("--clear-at must be in 0 .. 1e9 ms");
      }
      else if (a == "--corrupt-page") {
        if (!(v = value(a.c_str()))) return bad("--corrupt-page needs a page number");
        corrupt_page = std::stoi(v);
        if (corrupt_page < 62 || corrupt_page > 63) return bad("--corrupt-page must be 62 or 63 (the data pages)");
      }
      else if (a == "--pour") rig.pour = true;
      else if (a == "--reset-before-pour") rig.reset_before_pour = true;
      else if (a == "--csv") {
        if (!(v = value(a.c_str()))) return bad("--csv needs a file");
        rig.csv = v;
        if (rig.csv.empty()) return bad("--csv needs a file");
      }
      else if (a == "--seed") {
        if (!(v = value(a.c_str()))) return bad("--seed needs a number");
        const long long s = std::stoll(v);
        if (s < 0 || s > 0xFFFFFFFFll) return bad("--seed must be in 0 .. 4294967295");
        rig.seed = static_cast<uint32_t>(s);
        ao.seed = static_cast<uint64_t>(s);
      } else if (a == "--estop-at") {
        if (!(v = value(a.c_str()))) return bad("--estop-at needs milliseconds");
        rig.estop_at_ms = std::stod(v);
        if (!(rig.estop_at_ms >= 0 && rig.estop_at_ms < 1e9)) return bad("--estop-at must be in 0 .. 1e9 ms");
      } else if (a == "--overcurrent-at") {
        if (!(v = value(a.c_str()))) return bad("--overcurrent-at needs milliseconds");
        overcurrent_at_ms = std::stod(v);
        if (!(overcurrent_at_ms >= 0 && overcurrent_at_ms < 1e9)) return bad("--overcurrent-at must be in 0 .. 1e9 ms");
      } else if (a == "--overcurrent-a") {
        if (!(v = value(a.c_str()))) return bad("--overcurrent-a needs amperes");
        overcurrent_a = std::stod(v);
        if (!(std::fabs(overcurrent_a) <= 1000.0) || overcurrent_a == 0.0) return bad("--overcurrent-a must be in -1000 .. 1000 A, not 0");
      } else if (a == "--gear-stiffness") {
        if (!(v = value(a.c_str()))) return bad("--gear-stiffness needs N m/rad");
        rig.gear_stiffness = std::stod(v);
        if (!(rig.gear_stiffness >= 100 && rig.gear_stiffness <= 1e5)) return bad("--gear-stiffness must be in 100 .. 1e5 N m/rad");
      } else if (a == "--brake-ms") {
        if (!(v = value(a.c_str()))) return bad("--brake-ms needs milliseconds");
        rig.brake_ms = std::stod(v);
        if (!(rig.brake_ms >= 0 && rig.brake_ms <= 1000)) return bad("--brake-ms must be in 0 .. 1000");
      } else if (a == "--episode-s" || a == "--hold-s") {
        if (!(v = value(a.c_str()))) return bad(a + " needs seconds");
        const double s = std::stod(v);
        if (!(s > 0 && s <= 600)) return bad(a + " must be in (0, 600]");
        (a == "--episode-s" ? rig.episode_s : rig.hold_s) = s;
      } else {
        return bad("unknown option " + a + " (--help)");
      }
    } catch (const std::exception&) {
      return bad("bad number for " + a + ": " + (v ? v : ""));
    }
  }
  if (rig.reset_before_pour && !rig.pour) return bad("--reset-before-pour needs --pour");
  if (!rig.csv.empty() && !rig.pour) return bad("--csv needs --pour");
  if (rig.fill_at_ms >= 0 && !rig.empty) return bad("--fill-at needs --empty-rig");
  if ((rig.read_calibration || rig.clear_at_ms >= 0) && !(rig.world || rig.empty)) {
    return bad("--read-calibration and --clear-at need --world or --empty-rig");
  }
  if (!rig.csv.empty() && rig.csv == o.elf) return bad("--csv must not name the image");
  if ((rig.world ? 1 : 0) + (rig.empty ? 1 : 0) + (rig.pour ? 1 : 0) > 1) {
    return bad("--world, --empty-rig and --pour exclude each other (--pour fills the bucket itself)");
  }
  const bool with_rig = rig.world || rig.pour || rig.empty;
  if (!with_rig && (rig.estop_at_ms >= 0 || overcurrent_at_ms >= 0)) return bad("--estop-at and --overcurrent-at need --world, --empty-rig or --pour");
  if (rig.pour && !seconds_given) o.seconds = 60.0;
  rig.timeout_s = o.seconds;
  if (overcurrent_at_ms >= 0) {
    ao.fault_phase_overcurrent_a = overcurrent_a;
    ao.fault_at_s = overcurrent_at_ms * 1e-3;
  }
  for (double t : {rig.estop_at_ms, overcurrent_at_ms, o.stall_core_at_ms}) {
    if (t >= 0 && (rig.fault_at_ms < 0 || t < rig.fault_at_ms)) rig.fault_at_ms = t;
  }
  std::ifstream f(o.elf, std::ios::binary);
  if (!f) return bad("cannot read " + o.elf);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<uint8_t> flash;
  const std::string err = load_elf(o.elf, bytes, &flash);
  if (!err.empty()) return bad(err);
  if (corrupt_page >= 0) {
    // A block whose write stopped after its first double-word, programmed 0 (not the block's magic): the rest
    // of the page erased.
    std::fill_n(flash.begin() + static_cast<long>(corrupt_page) * 2048, 8, uint8_t{0});
  }
  std::fprintf(stderr, "virtual board: %s sha256 %s\n", o.elf.c_str(), sha256(bytes).c_str());
  vb::AnalogSet analog;  // before the board: the plant outlives the models (and the rig's load on it)
  vb::Board board(o);
  board.load(flash);
  analog = vb::make_analog_models(ao);
  for (auto& m : analog.peripherals) board.add_model(std::move(m));
  board.add_model(std::make_unique<PlantStep>(analog.plant.get()));
  vb::Rig* the_rig = nullptr;
  if (with_rig) {
    auto r = std::make_unique<vb::Rig>(rig, &board, analog.plant.get());
    if (!r->error().empty()) return bad(r->error());
    the_rig = r.get();
    r->watch(analog.tim1);
    board.add_model(std::move(r));  // after the plant: each step's frame leaves once the world has stepped
  }
  const std::string e = board.init();
  if (!e.empty()) return bad(e);
  int rc = board.run();
  const double emu = static_cast<double>(board.now_ps()) / 1e12;
  if (board.first_heartbeat_ps() != UINT64_MAX) {
    std::printf("heartbeat at %.3f ms emulated\n", static_cast<double>(board.first_heartbeat_ps()) / 1e9);
  }
  if (bench || o.until_heartbeat) {
    std::printf("emulated %.3f s in %.3f s wall: ratio %.2f; %llu instructions, %llu exceptions, %llu frames, %u resets\n", emu,
                board.wall_s(), board.wall_s() > 0 ? emu / board.wall_s() : 0.0, (unsigned long long)board.instructions(),
                (unsigned long long)board.exceptions_taken(), (unsigned long long)board.frames_tx(), board.resets());
  }
  if (the_rig != nullptr) {
    const int rr = the_rig->report();
    if (rc == 0) rc = rr;
  }
  if (o.until_heartbeat && board.first_heartbeat_ps() == UINT64_MAX && rc == 0) {
    std::fprintf(stderr, "virtual board: no heartbeat within %.3f s\n", o.seconds);
    return 1;
  }
  return rc;
}
