// SPDX-License-Identifier: MIT
// The host side of the LCM loop: publishes the rig's sensor sample on POUR_SENSORS each tick (and the
// simulated plant's ground truth on POUR_TRUTH, which only the bench's tools read), applies the torque from
// POUR_TORQUE, publishes POUR_PARTICLES at a viewing rate. Lockstep (wait for each answer, deterministic) or real
// time (1 kHz wall clock, latest answer, misses counted and covered by safe torque).
#ifndef POURSIM_LCM_LINK_HPP
#define POURSIM_LCM_LINK_HPP

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "controllers.hpp"
#include "poursim/poursim.h"

namespace poursim {

struct LcmLinkDef {
  std::string url;               // empty: POUR_LCM_DEFAULT_URL
  bool lockstep = true;          // false: real time at 1 kHz wall clock
  int answer_timeout_ms = 2000;  // lockstep: no answer this long → error naming POUR_TORQUE
  int resend_ms = 100;           // lockstep: resend the sample after this long without an answer
  int rt_budget_us = 800;        // real time: how long a tick waits for the answer to its own sample
  int rt_safe_after_ms = 20;     // real time: no answer for this long → safe (zero) torque
  int particles_period_ms = 33;  // POUR_PARTICLES period in simulated time [ms]; 0: none
  bool truth_obs = false;        // POUR_TRUTH.obs from truth_norm's normalisation; false: all 0
  poursim_policy_t truth_norm{}; // the policy's theta_min, theta_max, omega_max (the rest unused)
  uint32_t expected_weights_hash = 0; // content hash the controller's policy must have; 0: any
                                      // (answers that report 0, e.g. from a CAN bridge, are not checked)
};

struct LcmLinkStats {
  int64_t samples_sent = 0;   // distinct sensor samples (resends not counted)
  int64_t resends = 0;       // lockstep: samples sent again after resend_ms
  int64_t answers = 0;       // decoded answers to our samples
  int64_t on_time = 0;       // answers that arrived before their tick's torque was applied
  int64_t late = 0;          // real time: answers that came after their tick was stepped
  int64_t stale_answers = 0; // answers to samples we no longer wait for (duplicates, other episodes)
  int64_t dropped = 0;       // messages on POUR_TORQUE that failed to decode (foreign, truncated)
  int64_t safe_ticks = 0;    // real time: ticks stepped with safe torque (no recent answer)
  int64_t overruns = 0;      // real time: ticks that started more than one period late
  int64_t late_max_us = 0;   // real time: worst tick-start lateness [µs]
  int64_t particles_sent = 0;
  int64_t fault_answers = 0; // answers given in FAULT or E-STOP mode (safe or zero torque)
  int last_mode = -1;        // controller mode of the latest answer (pour_mode_t), -1 before any
  int last_faults = 0;       // its latched fault bits
  uint32_t controller_weights_hash = 0; // weights.h content hash the controller reports
  std::vector<int32_t> rtt_us; // round trip per on-time or late answer [µs], sample publish → answer
};

class LcmLink {
 public:
  // Opens LCM and subscribes to POUR_TORQUE. nullptr with *err set on failure.
  static std::unique_ptr<LcmLink> open(const LcmLinkDef &def, std::string *err);
  ~LcmLink();
  LcmLink(const LcmLink &) = delete;
  LcmLink &operator=(const LcmLink &) = delete;

  // Publishes the sensor sample in obs (seq = obs.step; its truth on POUR_TRUTH) and gives the torque
  // command to apply now, as a fraction of tau_max in Q15 (the controller's pour_control_output_t.torque).
  // Lockstep: blocks for the answer; false with *err naming the channel after answer_timeout_ms. Real
  // time: sleeps to the tick's slot first. Both: false with *err if the controller runs other weights than expected.
  bool exchange(int episode, const poursim_obs_t &obs, int16_t *torque_q15, std::string *err);

  // Publishes POUR_PARTICLES if particles_period_ms of simulated time passed since the last one.
  void maybe_publish_particles(const poursim_world_t *world, const poursim_obs_t &obs);

  // Reads whatever answers are still in flight (for a final count); waits at most wait_ms.
  void drain(int wait_ms);

  // Asks the controller for a new run (POUR_COMMAND clear_faults + stop + reset): it has no episodes of its
  // own. A new episode is a new simulated rig, which in-process gets a freshly initialised core, faults of the
  // last episode cleared; the three requests together give the remote core exactly that state.
  void request_new_run();

  // Policy action index of the answer in use (-1 before the first answer of an episode).
  int last_action() const;

  const LcmLinkStats &stats() const;
  const LcmLinkDef &def() const;

  // Median and 99th percentile of stats().rtt_us [µs]; 0 if there are none.
  void rtt_percentiles(double *median_us, double *p99_us) const;

  // One line: mode, counts, latency.
  std::string summary() const;

  struct Impl;

 private:
  explicit LcmLink(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// host_sim's controller across LCM: each command() is one exchange with pour_controller. A lockstep
// timeout prints the error naming the channel and ends the process with exit status 3 (the pour cannot
// go on without its controller).
class LcmController : public Controller {
 public:
  static std::unique_ptr<LcmController> open(const LcmLinkDef &def, std::string *err);
  std::string name() const override;
  void reset(uint32_t seed) override;
  double command(const poursim_obs_t &obs) override;
  int action() const override { return link_->last_action(); }
  bool failed() const override { return failure_status_ != 0; }
  std::string failure() const override { return failure_; }
  // After a failure, the exit status it means in every pour program: 3 the controller does not answer,
  // 4 it answers with other weights than expected_weights_hash; 0 while there is none.
  int failure_status() const { return failure_status_; }
  // Particles are published from this world at the link's viewing rate (nullptr: none).
  void set_world(const poursim_world_t *world) { world_ = world; }
  LcmLink &link() { return *link_; }

 private:
  explicit LcmController(std::unique_ptr<LcmLink> link) : link_(std::move(link)) {}
  std::unique_ptr<LcmLink> link_;
  const poursim_world_t *world_ = nullptr;
  int episode_ = -1;
  bool warned_ = false;
  std::string failure_;
  int failure_status_ = 0;
};

} // namespace poursim

#endif // POURSIM_LCM_LINK_HPP
