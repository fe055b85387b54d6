// SPDX-License-Identifier: MIT
// The bench around the virtual board: the rig's sensor node, its bucket, the brake, and the host's script
// (rig.hpp).
#include "rig.hpp"

#include "../analog/models.hpp"  // the analog models (virtual_board/analog): Tim1

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>

extern "C" {
#include "pour/can_node.h"
}

namespace vb {

namespace {
constexpr double kDeg = 180.0 / 3.141592653589793;
constexpr unsigned kBrakePort = 1, kBrakePin = 3;   // PB3 (pour/board_facts.h POUR_BOARD_PIN_BRAKE)
constexpr unsigned kEstopPort = 1, kEstopPin = 8;   // PB8 (POUR_BOARD_PIN_ESTOP)
constexpr unsigned kPowerPort = 0, kPowerPin = 15;  // PA15, high = the power stage on (POUR_BOARD_PIN_POWER)
const char* mode_name(int m) {
  switch (m) {
    case 0: return "IDLE";
    case 1: return "RUN";
    case 2: return "FAULT";
    case 3: return "ESTOP";
    default: return "none";
  }
}
}  // namespace

Rig::Rig(const RigOptions& o, Board* board, Plant* plant)
    : Peripheral("rig (sensor node, bucket, host)", 0, 0), o_(o), board_(board), plant_(plant) {
  wo_.seed = o.seed;
  if (o.gear_stiffness > 0.0) {
    // the damping scaled to keep its share of critical (WorldCouplingOptions: about 0.5)
    wo_.damping_nms *= std::sqrt(o.gear_stiffness / wo_.stiffness_nm_per_rad);
    wo_.stiffness_nm_per_rad = o.gear_stiffness;
  }
  node_ = pour_can_node_default_config().node_id;  // until the board's first frame names its node
  if (o_.pour || o_.empty) {
    empty_ = std::make_unique<EmptyBucket>(wo_, plant_);
  } else {
    world_ = std::make_unique<WorldCoupling>(wo_, plant_);
    if (!world_->ok()) error_ = world_->error();
  }
  board_->on_tx = [this](const CanFrame& f) { frame(f); };
}

Rig::~Rig() { board_->on_tx = nullptr; }

double Rig::now_ms() const { return static_cast<double>(board_->now_ps()) / 1e9; }

double Rig::theta() const { return world_ ? world_->bucket_theta() : empty_ ? empty_->bucket_theta() : 0.0; }

void Rig::say(const char* fmt, ...) {
  char b[320];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(b, sizeof b, fmt, ap);
  va_end(ap);
  log_ += b;
  log_ += "\n";
}

void Rig::fail(const std::string& why) {
  if (stage_ == Stage::Failed) return;
  error_ = why;
  stage_ = Stage::Failed;
  board_->finish();
}

void Rig::send(uint8_t cmd) {
  pour_can_frame_t f;
  if (pour_can_pack_command(node_, cmd, &f) != POUR_OK) {
    fail("cannot pack command " + std::to_string(cmd));
    return;
  }
  CanFrame c{f.id, f.dlc, {}};
  std::memcpy(c.data, f.data, 8);
  board_->receive_frame(c);
}

void Rig::reset() {
  // Called at power-on too (Board::init): nothing to do then.
  if (!powered_) {
    powered_ = true;
    return;
  }
  ++resets_;
  heartbeat_ = false;
  mode_ = -1;
  if (fill_on_reset_) {
    // The board held in reset while the bench fills the bucket.
    fill_on_reset_ = false;
    fill();
  }
}

void Rig::fill() {
  // The empty rig gives way to host_sim's world, the bucket mounted where the shaft stands, held by the brake.
  say("fill at %.1f ms: the motor shaft at %.4f rad (%.1f electrical deg from where it stood at power-on)", now_ms(),
      plant_->theta(), std::fmod(plant_->theta() * plant_->pole_pairs() * kDeg, 360.0));
  empty_.reset();
  world_ = std::make_unique<WorldCoupling>(wo_, plant_);
  if (!world_->ok()) fail(world_->error());
  world_->set_brake(brake_);
  sent_step_ = UINT32_MAX;
}

void Rig::frame(const CanFrame& cf) {
  pour_can_frame_t f;
  f.id = static_cast<uint16_t>(cf.id);
  f.dlc = cf.dlc;
  std::memcpy(f.data, cf.data, 8);
  node_ = static_cast<uint8_t>(f.id >> POUR_CAN_NODE_SHIFT);
  const double now = now_ms();
  switch (f.id & POUR_CAN_CMD_MASK) {
    case POUR_CAN_CMD_HEARTBEAT: {
      pour_can_heartbeat_t h;
      if (pour_can_unpack_heartbeat(&f, &h) == POUR_CAN_RX_OK) {
        if (!heartbeat_) stage_ms_ = std::max(stage_ms_, now);
        heartbeat_ = true;
        mode_ = h.mode;
        faults_ = h.faults;
        held_ = h.held != 0u;
        if (fault_seen_ms_ >= 0.0 && mode_ == POUR_MODE_RUN && rerun_ms_ < 0.0) rerun_ms_ = now;
      }
      break;
    }
    case POUR_CAN_CMD_IDENTITY: {
      pour_can_identity_t id;
      if (pour_can_unpack_identity(&f, &id) == POUR_CAN_RX_OK) init_status_ = id.init_status;
      break;
    }
    case POUR_CAN_CMD_DRIVE_TELEMETRY: {
      pour_can_drive_telemetry_t d;
      if (pour_can_unpack_drive_telemetry(&f, &d) == POUR_CAN_RX_OK) drive_faults_ = d.drive_faults;
      break;
    }
    case POUR_CAN_CMD_TORQUE: {
      pour_can_torque_t t;
      if (pour_can_unpack_torque(&f, &t) == POUR_CAN_RX_OK) mode_ = t.mode;
      break;
    }
    case POUR_CAN_CMD_CALIBRATION_RESULT: {
      pour_can_calibration_result_t r;
      if (pour_can_unpack_calibration_result(&f, &r) != POUR_CAN_RX_OK) break;
      if (stage_ == Stage::Calibrating) {
        ++cal_results_;
        if (cal_results_ == 1 && r.status != POUR_CAN_CAL_MEASURING) {
          fail("the board refused the calibration: CalibrationResult status " + std::to_string(r.status) + " (can/pour.dbc)");
        } else if (cal_results_ >= 2) {
          cal_ = r;
          have_cal_ = true;
          say("calibration: status %u stored %u at %.1f ms (started at %.1f ms)", r.status, r.stored, now, stage_ms_);
          if (r.status != POUR_CAN_CAL_OK) {
            fail("the calibration failed: CalibrationResult status " + std::to_string(r.status) + " (can/pour.dbc)");
          } else {
            stage_ = o_.reset_before_pour ? Stage::Resetting : Stage::Filling;
            stage_ms_ = now;
          }
        }
      } else if (!o_.pour && r.status == POUR_CAN_CAL_STORED && read_sent_ && !have_readback_) {
        readback_ = r;
        have_readback_ = true;
        init_after_reset_ = init_status_;
      } else if (stage_ == Stage::ReadBack && r.status == POUR_CAN_CAL_STORED) {
        readback_ = r;
        have_readback_ = true;
        stage_ms_ = now;
        if (run_ms_ < 0.0) {
          stage_ = Stage::Pour;
        } else {
          stage_ = Stage::Done;
          board_->finish();
        }
      }
      break;
    }
    default:
      break;
  }
}

void Rig::advance() {
  if (stage_ == Stage::Failed) return;
  const double now = now_ms();
  // The holding brake follows PB3: engaged unless the pin is driven high (the external pull-down); a
  // spring-applied brake holds brake_ms after its coil is cut, and lets go at once when it is energised.
  const bool asked = !board_->gpio(kBrakePort).driven_high(kBrakePin);
  if (asked != line_engaged_) {
    line_engaged_ = asked;
    line_ms_ = now;
  }
  const bool engaged = line_engaged_ && now >= line_ms_ + o_.brake_ms;
  if (engaged != brake_ || sent_step_ == UINT32_MAX) {
    brake_ = engaged;
    if (world_) world_->set_brake(engaged);
    if (empty_) empty_->set_brake(engaged);
  }
  if (world_ && !world_->ok()) {
    fail(world_->error());
    return;
  }
  // The rig's sensor node: one Sensors frame per physics step, as it arrives from the bus.
  const uint32_t steps = world_ ? world_->steps() : empty_ ? empty_->steps() : 0u;
  if (steps != sent_step_ && streaming_) {
    pour_can_frame_t f;
    const bool ok = world_ ? world_->sensors_frame(node_, &f) : empty_->sensors_frame(node_, &f);
    if (ok) {
      CanFrame c{f.id, f.dlc, {}};
      std::memcpy(c.data, f.data, 8);
      board_->receive_frame(c);
      board_->to_bus(c);  // bridged: the rig's node is on the bus too
    }
    sent_step_ = steps;
  }
  // Faults at their times.
  if (o_.estop_at_ms >= 0.0 && !estop_opened_ && now >= o_.estop_at_ms) {
    board_->gpio(kEstopPort).external[kEstopPin] = 1;  // the normally-closed contact opens: the pull-up wins
    estop_opened_ = true;
  }
  // The angle where the fault began: the last one seen before its time (a stalled core's slice ends after it).
  if (o_.fault_at_ms >= 0.0 && !fault_theta_taken_ && now < o_.fault_at_ms) theta_before_fault_ = theta();
  if (o_.fault_at_ms >= 0.0 && !fault_theta_taken_ && now >= o_.fault_at_ms) {
    theta_fault_ = theta_before_fault_;
    mode_at_fault_ = mode_;
    fault_theta_taken_ = true;
  }
  if (fault_theta_taken_ && moe_off_ms_ < 0.0 && tim1_ != nullptr && !tim1_->moe()) moe_off_ms_ = now;
  if (fault_theta_taken_ && power_off_ms_ < 0.0 && !board_->gpio(kPowerPort).driven_high(kPowerPin)) power_off_ms_ = now;
  if (fault_theta_taken_ && brake_on_ms_ < 0.0 && brake_) brake_on_ms_ = now;
  if (fault_theta_taken_) theta_max_after_fault_ = std::max(theta_max_after_fault_, std::fabs(theta() - theta_fault_));
  // The episode's trajectory, as host_sim --csv writes it (the columns the two have in common).
  if (!o_.csv.empty() && world_ && run_ms_ >= 0.0 && !have_episode_ && world_->steps() != csv_step_) {
    csv_step_ = world_->steps();
    const poursim_obs_t& ob = world_->obs();
    char line[200];
    const uint32_t k = csv_step_ - run_step_;
    std::snprintf(line, sizeof line, "%u,%u,%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%d\n", o_.seed, k, k * 1e-3, ob.theta, ob.omega,
                  ob.v_rotating, ob.v_target, ob.v_spill, ob.v_flight, world_->gear_torque(), mode_);
    csv_ += line;
  }
  if (!o_.pour) {
    // pour-bench calibration: what the boot found in the calibration page.
    if (o_.read_calibration && heartbeat_ && !read_sent_ && now >= stage_ms_ + 50.0) {
      send(POUR_CAN_CMD_CALIBRATION_READ);
      read_sent_ = true;
    }
    if (o_.clear_at_ms >= 0.0 && !clear_sent_ && now >= o_.clear_at_ms) {
      send(POUR_CAN_CMD_CLEAR_ERRORS);
      clear_sent_ = true;
    }
    if (clear_sent_ && mode_ == POUR_MODE_RUN) mode_after_clear_ = POUR_MODE_RUN;
    if (o_.fill_at_ms >= 0.0 && empty_ && now >= o_.fill_at_ms && brake_) {
      fill();
      std::fprintf(stderr, "virtual board: the bucket filled at %.1f ms\n", now);  // at once: a bench waits for it
      std::fflush(stderr);
    }
    theta_end_ = theta();
    end_ms_ = now;
    return;
  }
  if (now > o_.timeout_s * 1e3 && stage_ != Stage::Done) {
    fail("the script did not end within " + std::to_string(o_.timeout_s) + " s emulated");
    return;
  }
  switch (stage_) {
    case Stage::Boot:
      // pour-bench calibrate: the node is up (its heartbeat), then CalibrationStart.
      if (heartbeat_ && now >= stage_ms_ + 100.0) {
        send(POUR_CAN_CMD_CALIBRATION_START);
        stage_ = Stage::Calibrating;
        stage_ms_ = now;
      }
      break;
    case Stage::Calibrating:
      if (now > stage_ms_ + 15000.0) fail("no calibration outcome within 15 s");
      break;
    case Stage::Filling:
      // The bench fills the bucket while the board holds it (the calibration's end engaged the brake).
      if (now >= stage_ms_ + 200.0 && brake_) {
        fill();
        stage_ = Stage::Pour;
        stage_ms_ = now;
      } else if (now > stage_ms_ + 2000.0) {
        fail("the brake did not engage after the calibration: the bucket cannot be filled");
      }
      break;
    case Stage::Resetting:
      if (now >= stage_ms_ + 200.0) {
        fill_on_reset_ = !world_;
        ++script_resets_;
        board_->request_reset(fill_on_reset_ ? "the bench's reset (NRST), the bucket filled meanwhile" : "the bench's reset (NRST)");
        stage_ = Stage::ReadBack;
        stage_ms_ = now;
      }
      break;
    case Stage::ReadBack:
      // pour-bench calibration: the block as the new boot read it from flash.
      if (heartbeat_ && init_after_reset_ == 99 && now >= stage_ms_ + 50.0) {
        init_after_reset_ = init_status_;
        send(POUR_CAN_CMD_CALIBRATION_READ);
      }
      if (now > stage_ms_ + 2000.0) fail("no answer to CalibrationRead after the reset");
      break;
    case Stage::Pour:
      if (run_ms_ < 0.0) {
        if (mode_ == POUR_MODE_RUN) {
          run_ms_ = now;
          run_step_ = world_ ? world_->steps() : 0u;
        } else if (mode_ == POUR_MODE_IDLE && held_ && now >= last_reset_ms_ + 300.0) {
          send(POUR_CAN_CMD_RESET);  // pour-bench reset: the board boots held, and a clear leaves it held
          last_reset_ms_ = now;
        } else if (mode_ == POUR_MODE_FAULT && now >= last_clear_ms_ + 300.0) {
          send(POUR_CAN_CMD_CLEAR_ERRORS);  // pour-bench clear: a board that latched the wait in FAULT
          last_clear_ms_ = now;
        } else if (now > stage_ms_ + 3000.0 && init_status_ < 0 && init_status_ != 99) {
          refused_status_ = init_status_;  // RUN refused by name (Identity.InitStatus): the pour ends held
          stop_ms_ = now;
          stage_ = Stage::Stopped;
        } else if (now > stage_ms_ + 3000.0) {
          fail(std::string("the board did not enter RUN within 3 s of the fill (mode ") + mode_name(mode_) + ")");
        }
        break;
      }
      if (world_ && world_->steps() - run_step_ >= static_cast<uint32_t>(std::lround(o_.episode_s * 1e3))) {
        have_episode_ = true;
        poured_ = world_->poured();
        spilled_ = world_->spilled();
        theta_episode_ = world_->bucket_theta();
        // host_sim's episode is over: the host stops forwarding the rig's samples (as host_sim's episodes over
        // the CAN bridge end) and sends Stop (pour-bench stop).
        streaming_ = false;
        send(POUR_CAN_CMD_STOP);
        stop_ms_ = now;
        stage_ = Stage::Stopped;
      } else if (fault_seen_ms_ < 0.0 && (mode_ == POUR_MODE_FAULT || mode_ == POUR_MODE_ESTOP || resets_ > script_resets_)) {
        fault_seen_ms_ = now;
        say("fault: seen at %.1f ms (mode %s, faults 0x%04x, resets %u)", now, mode_name(mode_), faults_, resets_ - script_resets_);
        stop_ms_ = now;
        stage_ = Stage::Stopped;
      }
      break;
    case Stage::Stopped:
      if (now >= stop_ms_ + o_.hold_s * 1e3) {
        theta_end_ = theta();
        end_ms_ = now;
        if (fault_seen_ms_ < 0.0 && !have_readback_) {
          stage_ = Stage::Resetting;  // the stored calibration, read back after a reset of the board
          stage_ms_ = now;
          heartbeat_ = false;
          init_after_reset_ = 99;
        } else {
          stage_ = Stage::Done;
          board_->finish();
        }
      }
      break;
    case Stage::Done:
    case Stage::Failed:
      break;
  }
}

int Rig::report() {
  std::fputs(log_.c_str(), stdout);
  if (!o_.csv.empty()) {
    // Written beside its target and renamed over it when complete.
    const std::string tmp = o_.csv + ".tmp";
    FILE* f = std::fopen(tmp.c_str(), "w");
    bool ok = f != nullptr;
    if (ok) {
      ok = std::fputs("seed,step,t_s,theta_rad,omega_rad_s,v_rotating,v_target,v_spill,v_flight,gear_torque_nm,mode\n", f) >= 0 &&
           std::fputs(csv_.c_str(), f) >= 0;
      ok = std::fclose(f) == 0 && ok;
    }
    if (!ok || std::rename(tmp.c_str(), o_.csv.c_str()) != 0) {
      std::remove(tmp.c_str());
      if (error_.empty()) error_ = "cannot write " + o_.csv;
    }
  }
  if (have_cal_) {
    const double r = cal_.resistance_mohm * 1e-3, l = cal_.inductance_uh * 1e-6;
    std::printf("calibration: R %.4f ohm (model %.4f, %+.2f %%), L %.1f uH (model %.1f, %+.2f %%), pole pairs %u (model %d)\n", r,
                plant_->r_phase(), 100.0 * (r / plant_->r_phase() - 1.0), l * 1e6, plant_->l_phase() * 1e6,
                100.0 * (l / plant_->l_phase() - 1.0), cal_.pole_pairs, plant_->pole_pairs());
  }
  if (have_readback_ && !o_.pour) {
    std::printf("calibration read: init status %d, stored %u (can/pour.dbc CalibrationResult.Stored: 0 OK, 1 EMPTY, 2 CORRUPT)\n",
                init_after_reset_, readback_.stored);
  } else if (have_readback_) {
    std::printf("read back after the reset: init status %d, stored %u, R %.4f ohm, L %.1f uH, pole pairs %u%s\n",
                init_after_reset_, readback_.stored, readback_.resistance_mohm * 1e-3, static_cast<double>(readback_.inductance_uh),
                readback_.pole_pairs,
                readback_.resistance_mohm == cal_.resistance_mohm && readback_.inductance_uh == cal_.inductance_uh &&
                        readback_.pole_pairs == cal_.pole_pairs && readback_.electrical_offset == cal_.electrical_offset
                    ? " (as measured)"
                    : " (differs from the measurement)");
  }
  if (run_ms_ >= 0.0) std::printf("pour: RUN at %.1f ms (world step %u)\n", run_ms_, run_step_);
  if (refused_status_ != 0) std::printf("pour: RUN refused for 3 s, init status %d (pour_status_t)\n", refused_status_);
  if (have_episode_) {
    std::printf("episode (%.3f s after RUN): poured %.2f %%, spilled %.2f %%, theta %.2f deg\n", o_.episode_s, 100.0 * poured_,
                100.0 * spilled_, theta_episode_ * kDeg);
  }
  if (fault_theta_taken_) {
    std::printf("fault at %.1f ms: theta %.2f deg (mode %s); moved at most %.2f deg after it\n", o_.fault_at_ms, theta_fault_ * kDeg,
                mode_name(mode_at_fault_), theta_max_after_fault_ * kDeg);
    if (moe_off_ms_ >= 0.0) std::printf("TIM1 MOE 0 (the bridge off) %.3f ms after the fault\n", moe_off_ms_ - o_.fault_at_ms);
    if (power_off_ms_ >= 0.0) std::printf("PA15 low (the power stage off) %.3f ms after the fault\n", power_off_ms_ - o_.fault_at_ms);
    if (brake_on_ms_ >= 0.0) std::printf("the brake holding %.3f ms after the fault\n", brake_on_ms_ - o_.fault_at_ms);
  }
  if (clear_sent_) {
    std::printf("after ClearErrors at %.1f ms: %s\n", o_.clear_at_ms,
                mode_after_clear_ == POUR_MODE_RUN ? "RUN was entered" : "RUN never entered");
  }
  if (end_ms_ >= 0.0) {
    std::printf("end at %.1f ms: theta %.2f deg, brake %s, mode %s, faults 0x%04x, resets %u, drive faults 0x%04x, held %d\n",
                end_ms_, theta_end_ * kDeg, brake_ ? "engaged" : "released", mode_name(mode_), faults_, resets_ - script_resets_,
                drive_faults_, held_ ? 1 : 0);
    if (fault_seen_ms_ >= 0.0) {
      if (rerun_ms_ < 0.0) std::printf("after the fault: RUN never re-entered\n");
      else std::printf("after the fault: RUN again at %.1f ms\n", rerun_ms_);
    }
    if (world_) std::printf("world: poured %.2f %%, spilled %.2f %%, left %.2f %%\n", 100.0 * world_->poured(), 100.0 * world_->spilled(),
                            100.0 * world_->remaining());
  }
  if (!error_.empty()) {
    std::fprintf(stderr, "virtual board: %s\n", error_.c_str());
    return 1;
  }
  if (o_.pour && stage_ != Stage::Done) {
    std::fprintf(stderr, "virtual board: the --pour script did not end (raise --seconds)\n");
    return 1;
  }
  return 0;
}

}  // namespace vb
