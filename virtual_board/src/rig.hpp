// SPDX-License-Identifier: MIT
// The bench around the virtual board, without SocketCAN (issue 37's closed loop): the rig's sensor node and
// the host's commands, in lockstep with the emulated clock.
//   - the rig: the bucket behind the gear (vb::WorldCoupling, host_sim's world; before the fill vb::EmptyBucket),
//     its Sensors frame (the output encoder and both scales) into FDCAN1's RX path at every 1 ms physics step
//     as a frame from the bus arrives (Board::receive_frame, the entry the SocketCAN bridge uses), and the
//     holding brake driven by the board's brake line (PB3, high = released: pour/board_facts.h,
//     docs/bringup.md; the external pull-down engages it whenever the pin is not driven high);
//   - the host (--pour): what pour-bench would send, at emulated times and on the answers: CalibrationStart,
//     the calibration's outcome, a reset of the board (the bucket filled meanwhile), CalibrationRead, a
//     ClearErrors if the board waits in FAULT, the pour, a Stop when host_sim's episode (10 s) ends;
//   - faults at emulated times: the e-stop contact opened (PB8 reads high).
// Deterministic: no wall clock, the world and the scales' noise seeded.
#ifndef POUR_VIRTUAL_BOARD_RIG_HPP
#define POUR_VIRTUAL_BOARD_RIG_HPP

#include <cstdint>
#include <memory>
#include <string>

#include "analog.hpp"
#include "board.hpp"
#include "world_coupling.hpp"

namespace vb {

struct RigOptions {
  bool world = false;        // --world: the filled bucket's world behind the gear from power-on
  bool empty = false;        // --empty-rig: the empty bucket from power-on (pour-bench calibrate over a bus)
  bool read_calibration = false;  // --read-calibration: CalibrationRead 50 ms after the first heartbeat
  double clear_at_ms = -1.0;      // --clear-at MS: ClearErrors at this emulated time (pour-bench clear)
  double fill_at_ms = -1.0;       // --fill-at MS: with --empty-rig, the bucket filled then (once the brake holds)
  bool pour = false;         // --pour: the empty rig, calibrate, fill (held), pour, stop, reset, read back
  bool reset_before_pour = false;  // --reset-before-pour: the fill while the board is held in reset, the
                                   // read-back after it, then the pour (docs/virtual-board.md: the finding)
  uint32_t seed = 1;         // the world's (liquid, scales' noise)
  double episode_s = 10.0;   // host_sim's episode: poured and spilled are read this long after RUN began
  double hold_s = 1.5;       // after the Stop or a fault: how long the bucket is watched
  double estop_at_ms = -1.0; // the e-stop contact opens at this emulated time [ms]
  double fault_at_ms = -1.0; // the earliest injected fault (e-stop, overcurrent, a stalled core) [ms]
  double timeout_s = 60.0;   // a script that has not ended by then fails
  // The spring-applied brake holds this long after PB3 falls (assumed, as tests/board/
  // test_board_calibration_run.cpp's brake: no vendor figure for the rig's brake) [ms].
  double brake_ms = 20.0;
  double gear_stiffness = 0.0;  // --gear-stiffness: the gear's spring [N m/rad]; 0 WorldCouplingOptions' (2000)
  std::string csv;           // --csv FILE: the world's every step from RUN on (host_sim --csv's columns)
};

class Rig : public Peripheral {
 public:
  Rig(const RigOptions& o, Board* board, Plant* plant);
  ~Rig() override;
  bool read(uint32_t, unsigned, uint32_t*) override { return false; }
  bool write(uint32_t, unsigned, uint32_t) override { return false; }
  void reset() override;   // a reset of the chip: the rig and the host carry on (a fill waits for one)
  void advance() override;
  void frame(const CanFrame& f);  // every frame the board puts on the bus
  // The summary lines (stdout) and the script's status: 0 when it ran to its end, 1 if it failed (why, on
  // stderr), 3 if the bars of the run were not met (see docs/virtual-board.md).
  int report();
  const std::string& error() const { return error_; }
  // The bridge's timer, to time when its outputs went off after an injected fault (MOE: the break's cut).
  void watch(const Tim1* tim1) { tim1_ = tim1; }

 private:
  enum class Stage { Boot, Calibrating, Filling, Resetting, ReadBack, Pour, Stopped, Done, Failed };
  void fill();
  double now_ms() const;
  double theta() const;
  void send(uint8_t cmd);
  void fail(const std::string& why);
  void say(const char* fmt, ...);

  RigOptions o_;
  const Tim1* tim1_ = nullptr;
  double moe_off_ms_ = -1.0;  // the first time at or after the fault that TIM1's MOE read 0
  double power_off_ms_ = -1.0, brake_on_ms_ = -1.0;  // ... that PA15 (power) was low, the brake held
  Board* board_;
  Plant* plant_;
  WorldCouplingOptions wo_;
  std::unique_ptr<EmptyBucket> empty_;
  std::unique_ptr<WorldCoupling> world_;
  uint8_t node_ = 0;
  uint32_t sent_step_ = UINT32_MAX;
  bool brake_ = true, fill_on_reset_ = false, streaming_ = true;
  bool line_engaged_ = true;  // PB3's level asks for the brake
  double line_ms_ = -1e9;
  Stage stage_ = Stage::Boot;
  std::string error_;
  // what the board said
  bool heartbeat_ = false;
  int mode_ = -1, init_status_ = 99;
  uint16_t faults_ = 0, drive_faults_ = 0;  // Heartbeat's, DriveTelemetry's (pour/drive_faults.h)
  double stage_ms_ = 0.0, last_clear_ms_ = -1e9, last_reset_ms_ = -1e9;
  bool held_ = false;       // Heartbeat's Held: the board waits for a Reset
  int refused_status_ = 0;  // Identity.InitStatus when the board refused RUN for 3 s after the fill
  double rerun_ms_ = -1.0;  // RUN seen again after the fault (the board restarting on its own)
  int cal_results_ = 0;
  pour_can_calibration_result_t cal_{}, readback_{};
  bool have_cal_ = false, have_readback_ = false, read_sent_ = false, clear_sent_ = false;
  int mode_after_clear_ = -1;
  int init_after_reset_ = 99;
  unsigned resets_ = 0, script_resets_ = 0;  // chip resets after power-on; the script's
  bool powered_ = false;
  // the pour
  double run_ms_ = -1.0, stop_ms_ = -1.0, fault_seen_ms_ = -1.0, end_ms_ = -1.0;
  uint32_t run_step_ = 0;
  bool have_episode_ = false;
  double poured_ = 0, spilled_ = 0, theta_episode_ = 0;
  double theta_before_fault_ = 0.0, theta_fault_ = 0.0, theta_end_ = 0.0, theta_max_after_fault_ = 0.0;
  bool fault_theta_taken_ = false;
  int mode_at_fault_ = -1;
  bool estop_opened_ = false;
  std::string log_, csv_;
  uint32_t csv_step_ = UINT32_MAX;
};

}  // namespace vb

#endif
