// SPDX-License-Identifier: MIT
// The virtual board's rotor coupled to host_sim's bucket world (issue 37): the Plant's motor shaft drives
// the rotating bucket through the gear (gear_ratio motor turns per output turn, host_sim's config), and the
// bucket's Box2D world (liquid, both scales, the joint's Coulomb friction and holding brake) pushes back.
//
//   vb::AnalogSet set = vb::make_analog_models(o);
//   vb::WorldCoupling world(vb::WorldCouplingOptions{}, set.plant.get());   // installs the plant's load
//   ... run the board: each 1 kHz physics step is taken from inside the plant's PWM periods ...
//   world.sensors();   // the scales, for the board's CAN bridge (Sensors frames)
//
// The gear is a torsional spring and damper between the shaft ((theta_m - its angle when the bucket was
// coupled) / N) and the bucket (theta_b), behind a gearbox that loses (1 - eta) of the power crossing it
// (gear_load_at_motor): the
// plant's rotor integrates at the PWM rate, the bucket at the world's dt, each seeing the other's state of
// the last step (lockstep, no wall clock, deterministic for a seed). The world runs its ideal drive
// (drive 0) as a pure torque source: it applies the gear's average torque of the last physics step (after
// its fixed command_latency_ticks = 1 step), with its envelope opened (peak and no-load speed at their
// configurable maxima) and its rotor inertia 0, since the plant's rotor carries the motor's inertia.
#ifndef POUR_VB_WORLD_COUPLING_HPP
#define POUR_VB_WORLD_COUPLING_HPP

#include <cstdint>
#include <string>

#include "analog.hpp"
#include "poursim/poursim.h"

extern "C" {  // the C header carries no linkage of its own
#include "pour/can_codec.h"
}

namespace vb {
// The torque the gear's output torque tau_out puts on the motor [N m]: / N, and through the gearbox's
// efficiency eta, whose loss the motor pays when it drives (tau_out and the shaft's speed omega_m one way)
// and the bucket pays when it drives the motor.
double gear_load_at_motor(double tau_out, double omega_m, double ratio, double eta);
double default_gear_efficiency();  // host_sim's full drive's (see WorldCouplingOptions::gear_efficiency)
}  // namespace vb

namespace vb {

struct WorldCouplingOptions {
  uint32_t seed = 1;              // the world's reset seed (liquid arrangement, load cells' noise)
  // The gear's torsional stiffness and damping at the output. Assumed (no vendor figure for the rig's
  // gearbox): 2000 N m/rad deflects 0.7 deg at the drive's 25 N m peak; the damping gives the rotor on
  // the spring about 0.5 of critical.
  double stiffness_nm_per_rad = 2000.0;
  double damping_nms = 4.4;
  // The gearbox's efficiency: it loses (1 - eta) of the power that crosses it, whichever way it flows, as
  // host_sim's full drive has it (host_sim/physics/foc_drive.cpp, which takes the value of the drive's
  // configuration, gear_efficiency_q15: 0.90; no vendor figure for the rig's gearhead). 0 takes that value.
  double gear_efficiency = 0.0;
  bool brake = false;             // the holding brake engaged from the start
};

// What the host reads from the rig and sends the board in Sensors frames (poursim_obs_t: the output shaft's
// absolute encoder and the two load cells, tared empty), with the step they are for.
struct WorldSensors {
  uint32_t step = 0;
  uint32_t encoder = 0;
  int32_t scale_rotating_g = 0;
  int32_t scale_target_g = 0;
};

class WorldCoupling {
 public:
  // Creates and resets the world and installs the plant's load; on bad options (stiffness not > 0, damping
  // < 0, either not finite) or a world that does not settle, ok() is false, error() says why in one line
  // and the plant keeps no load.
  WorldCoupling(const WorldCouplingOptions& o, Plant* plant);
  ~WorldCoupling();
  WorldCoupling(const WorldCoupling&) = delete;
  WorldCoupling& operator=(const WorldCoupling&) = delete;

  bool ok() const { return world_ != nullptr && error_.empty(); }
  const std::string& error() const { return error_; }
  void set_brake(bool engaged);

  const poursim_obs_t& obs() const { return obs_; }
  WorldSensors sensors() const;
  // The latest sample as the host's Sensors frame for `node_id` (pour/can_codec.h; the scales saturated to
  // the frame's +-POUR_CAN_SCALE_MAX_G as host_sim's experiment log sends them); false if it does not pack.
  bool sensors_frame(uint8_t node_id, pour_can_frame_t* frame) const;
  double bucket_theta() const { return obs_.theta; }   // [rad], 0 upright, + toward the target
  double poured() const { return obs_.v_target; }      // fraction of the liquid in the target
  double spilled() const { return obs_.v_spill; }
  double remaining() const { return obs_.v_rotating; }
  double gear_torque() const { return last_torque_; }  // at the output, applied in the last step [N m]
  uint32_t steps() const { return obs_.step; }
  uint64_t trajectory_hash() const;
  double gear_ratio() const { return n_; }

 private:
  double load(double t, double theta_m, double omega_m);  // the plant's load at the motor [N m]
  double eta_ = 1.0;
  poursim_world_t* world_ = nullptr;
  Plant* plant_ = nullptr;
  WorldCouplingOptions o_;
  std::string error_;
  poursim_obs_t obs_{};
  double n_ = 20.0, dt_ = 0.001, tau_max_ = 1000.0;
  double sum_ = 0.0, last_torque_ = 0.0;
  double theta_m0_ = 0.0, t0_ = 0.0;  // the shaft's angle and the plant's time when the bucket was coupled
  int samples_ = 0;
};

// The rig before the fill (the bench calibrates the drive with the rotating bucket empty: the interlock of
// firmware/ports/common/calibration_flow.h refuses more than 200 g on its scale): the empty bucket on its
// bearing through the same gear spring, a rigid inertia about its centre (its centre of mass on the axis: no
// gravity torque), host_sim's joint friction and holding brake, and the rig's sensors as the world's read
// (the output encoder of encoder_bits, both scales tared empty, with the load cells' noise).
class EmptyBucket {
 public:
  // Installs the plant's load; the gear's zero is the shaft's angle now.
  EmptyBucket(const WorldCouplingOptions& o, Plant* plant);
  ~EmptyBucket();
  EmptyBucket(const EmptyBucket&) = delete;
  EmptyBucket& operator=(const EmptyBucket&) = delete;
  void set_brake(bool engaged) { brake_ = engaged; }
  bool sensors_frame(uint8_t node_id, pour_can_frame_t* frame) const;
  double bucket_theta() const { return theta_; }
  uint32_t steps() const { return step_; }

 private:
  double load(double t, double theta_m, double omega_m);
  Plant* plant_;
  WorldCouplingOptions o_;
  double eta_ = 1.0;
  poursim_config_t c_{};
  double inertia_ = 0.0, theta_ = 0.0, omega_ = 0.0, theta_m0_ = 0.0, t0_ = 0.0, t_last_ = -1.0;
  uint32_t step_ = 0, encoder_ = 0;
  int32_t scale_rot_ = 0, scale_tgt_ = 0;
  bool brake_ = true;
  uint64_t rng_ = 0;
  double gauss();
};

}  // namespace vb

#endif
