// SPDX-License-Identifier: MIT
// host_sim --experiment: the controller's own identification experiment (pour/experiment.h) on the
// simulated rig, through the firmware's CAN node and core, written as the candump -L log a bench would
// record: the rig's Sensors frames, the ExperimentStart, and every frame the node sends (Torque each
// tick, Heartbeat and Identity every heartbeat period, the ParamAck that answers the start).
#ifndef POURSIM_EXPERIMENT_LOG_HPP
#define POURSIM_EXPERIMENT_LOG_HPP

#include <cstdint>
#include <string>

#include "poursim/poursim.h"

namespace poursim {

struct ExperimentRun {
  uint8_t kind = 1;      // pour_experiment_kind_t
  uint32_t seed = 1;     // the world's reset seed
  uint8_t node_id = 0;   // the controller's CAN node id, 0 .. 63
  std::string path;      // the candump -L log, written atomically
};

struct ExperimentResult {
  uint32_t ticks = 0;    // ticks logged [ms]
  uint8_t phase = 0;     // the Torque frames' Action at the end: pour_experiment_phase_t (DONE when it ran through)
  uint8_t mode = 0;      // the core's mode at the end (IDLE, held, when it ran through)
  uint16_t faults = 0;   // the core's fault bits at the end
};

// Runs it. The bucket is emptied first for the identify experiment; the tilt keeps the liquid. Returns
// false with the reason in *err when nothing could be run or written (a refused start, the world, the file);
// an experiment that ended early (out of range, a fault) is still logged, and *out says how it ended.
bool run_experiment(const poursim_config_t &config, const ExperimentRun &run, ExperimentResult *out,
                    std::string *err);

} // namespace poursim

#endif // POURSIM_EXPERIMENT_LOG_HPP
