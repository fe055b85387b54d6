// SPDX-License-Identifier: MIT
// What commands the bucket in host_sim: one interface, several implementations (the firmware core
// in-process, baselines; a controller across LCM plugs in the same way).
#ifndef POURSIM_CONTROLLERS_HPP
#define POURSIM_CONTROLLERS_HPP

#include <cstdint>
#include <memory>
#include <string>

extern "C" {
#include "pour/control.h"
#include "pour/safety.h"
#include "pour/sensors.h"
}
#include "poursim/poursim.h"
#include "poursim/weights_file.h"

namespace poursim {

class Controller {
 public:
  virtual ~Controller() = default;
  virtual std::string name() const = 0;
  // Called before every episode.
  virtual void reset(uint32_t seed) = 0;
  // The torque for the coming step as a fraction of tau_max, from the state s_t measured after the
  // last step. Called once per 1 ms tick.
  virtual double command(const poursim_obs_t &obs) = 0;
  // Index of the action in force (policies), -1 for baselines.
  virtual int action() const { return -1; }
  // Whether the controller can no longer command (a controller across LCM that stopped answering), and why.
  // After a failure command() returns 0 (no torque); the caller ends the run.
  virtual bool failed() const { return false; }
  virtual std::string failure() const { return {}; }
};

// The firmware core (pour_control_step) with a weights.h loaded at run time, fed the rig's sensor sample
// as it would cross the wire; its encoder resolution is the simulator's.
std::unique_ptr<Controller> make_firmware_controller(const poursim_weights_file_t &weights, bool sampled,
                                                     const poursim_config_t &config);

// Baselines, all seeing the rig through the firmware's estimator and commanding through its safety
// envelope (default config).
// Tilt at a constant rate [rad/s] to the stop, tracked by a PD loop (the paper's best binary policy).
std::unique_ptr<Controller> make_rate_controller(double rate, const poursim_config_t &config);
// +tau_max from start to end.
std::unique_ptr<Controller> make_full_torque_controller(const poursim_config_t &config);
// A hand-written good pour: quickly to just before the onset angle, then slowly on to the stop.
std::unique_ptr<Controller> make_hand_controller(const poursim_config_t &config);

// The sensor sample the firmware receives after a step (seq = the step).
pour_sensors_t to_sensor_sample(const poursim_obs_t &obs, uint32_t seq);

} // namespace poursim

#endif // POURSIM_CONTROLLERS_HPP
