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
#include "pour/sensors.h"
}
#include "poursim/poursim.h"
#include "poursim/weights_file.h"

namespace poursim {

class Controller {
 public:
  virtual ~Controller() = default;
  virtual std::string name() const = 0;
  // Called before every episode, after set_rig.
  virtual void reset(uint32_t seed) = 0;
  // The episode's rig as drawn from its seed: what a controller configured from the rig's file knows.
  virtual void set_rig(const poursim_config_t & /*rig*/) {}
  // The torque for the coming step as a fraction of tau_max, from the state s_t measured after the
  // last step. Called once per 1 ms tick.
  virtual double command(const poursim_obs_t &obs) = 0;
  // Index of the action in force (policies), -1 for baselines.
  virtual int action() const { return -1; }
  // Whether the controller can no longer command (a controller across LCM that stopped answering), and why.
  // After a failure command() returns 0 (no torque); the caller ends the run.
  virtual bool failed() const { return false; }
  virtual std::string failure() const { return {}; }
  // Whether the holding brake is to be engaged for the coming step (the firmware core's output).
  virtual bool brake() const { return false; }
  // The core's latched POUR_FAULT_* bits after the last command (0 for a controller without a core).
  virtual uint16_t faults() const { return 0; }
};

// The firmware's configuration for a simulated rig: its defaults, with the encoder as the simulator models
// it. Every in-process caller of the core (host_sim's controllers, the rollouts, Python's core handle)
// builds its config here.
pour_control_config_t firmware_config(const poursim_config_t &sim);

// The fill schedule's knee for a rig whose file gives its fill (config key fill_schedule_l; docs/safety.md):
// the angle at which a level liquid of the rig's fill reaches the lip, less kFillKneeMarginRad [rad].
constexpr double kFillKneeMarginRad = 3.0 * 3.14159265358979323846 / 180.0;
double fill_knee_rad(const poursim_config_t &rig);

// The firmware's one pipeline (pour_control_update, a decision, pour_control_shape) fed the rig's sensor
// sample each tick as it would cross the wire. The decision is decide()'s: the fixed-point policy of a
// weights.h, or a request from outside (a float policy, a baseline) through pour_control_request. The
// torque, the brake and the fault bits are the core's output.
class CoreController : public Controller {
 public:
  void reset(uint32_t seed) override;
  void set_rig(const poursim_config_t &rig) override { rig_ = rig; }
  double command(const poursim_obs_t &obs) override;
  // The pipeline's first stage alone on obs (estimate, supervise), ahead of the command(obs) that follows,
  // which then only decides and shapes: the Gymnasium stepper reads the state the latest step made.
  void sense(const poursim_obs_t &obs);
  int action() const override { return out_.action; }
  bool failed() const override { return status_ != POUR_OK; }
  std::string failure() const override;
  bool brake() const override { return status_ == POUR_OK && out_.brake; }
  uint16_t faults() const override { return out_.faults; }
  const pour_control_output_t &output() const { return out_; }
  const pour_control_t &core() const { return ctl_; } // the running core (its estimated state)
  // On (after the first episode): reset() restarts the same core by ClearErrors, Stop and Reset in the next
  // tick instead of initialising a fresh one, as a linked pour_controller is restarted between episodes.
  void restart_by_reset(bool on) { restart_by_reset_ = on; }

 protected:
  explicit CoreController(const poursim_config_t &sim) : sim_(sim), rig_(sim) {}
  // Initialises ctl for the episode with seed (pour_control_init or pour_control_init_external on config).
  virtual pour_status_t init(pour_control_t *ctl, const pour_control_config_t &config, uint32_t seed) = 0;
  // The decision when one is due, on the state the core estimated: pour_control_decide or _request.
  virtual void decide(pour_control_t *ctl, const pour_state_t &state) = 0;
  const poursim_config_t sim_;

 private:
  poursim_config_t rig_; // the episode's (set_rig), which the core's config is made for
  pour_control_t ctl_{};
  pour_control_output_t out_{};
  pour_status_t status_ = POUR_EINVAL;
  uint32_t seq_ = 0;
  bool restart_by_reset_ = false, restart_pending_ = false;
  bool sensed_ = false, due_ = false; // sense() ran for the next command(), and its verdict
};

// The firmware core (pour_control_step) with a weights.h loaded at run time, fed the rig's sensor sample
// as it would cross the wire; its encoder resolution is the simulator's.
std::unique_ptr<Controller> make_firmware_controller(const poursim_weights_file_t &weights, bool sampled,
                                                     const poursim_config_t &config, bool restart_by_reset);

// Baselines, each a request from outside into the firmware's pipeline (default config): they see the rig
// through its estimator and command through its envelope, supervisor and controlled stop.
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
