// SPDX-License-Identifier: MIT
// The experiment's log (experiment_log.hpp).
#include "experiment_log.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

extern "C" {
#include "pour/can_node.h"
#include "pour/control.h"
#include "pour/experiment.h"
}
#include "controllers.hpp"
#include "outputs.hpp"
#include "world.hpp"

namespace poursim {

namespace {

constexpr uint32_t kTailTicks = 1000; // logged after the experiment ended: the held bucket at rest (the scale's noise)
constexpr uint32_t kSpareTicks = 3000; // beyond the experiment's duration, a run that never ends is cut

// One frame as candump -L prints it: (seconds.micros) interface id#data, the time that of tick [ms].
void put_frame(std::FILE *f, uint32_t tick, const pour_can_frame_t &fr) {
  std::fprintf(f, "(%u.%06u) vcan0 %03X#", tick / 1000u, (tick % 1000u) * 1000u, static_cast<unsigned>(fr.id));
  for (unsigned i = 0; i < fr.dlc; ++i) std::fprintf(f, "%02X", fr.data[i]);
  std::fputc('\n', f);
}

int16_t wire_grams(int32_t g) { return static_cast<int16_t>(std::max(-POUR_CAN_SCALE_MAX_G, std::min(POUR_CAN_SCALE_MAX_G, g))); }

struct WorldGuard {
  poursim_world_t *w = nullptr;
  ~WorldGuard() { poursim_destroy(w); }
};

} // namespace

bool run_experiment(const poursim_config_t &cfg, const ExperimentRun &run, ExperimentResult *out, std::string *err) {
  char buf[POURSIM_ERR_LEN];
  if (cfg.tau_max * 100.0 > 65535.0) {
    *err = "tau_max above 655.35 N m does not fit Identity.TauMax";
    return false;
  }
  WorldGuard g{poursim_create(&cfg, buf, sizeof buf)};
  if (g.w == nullptr || poursim_reset(g.w, run.seed) != POURSIM_OK) {
    *err = std::string("the simulated world: ") + (g.w == nullptr ? buf : poursim_world_error(g.w));
    return false;
  }
  if (run.kind == POUR_EXPERIMENT_IDENTIFY) {
    // The bucket empty, then at rest upright: the joint held the liquid's weight until it went.
    empty_bucket(g.w, false);
    for (int k = 0; k < static_cast<int>(std::lround(0.2 / cfg.dt)); ++k) poursim_step_servo(g.w, 0.0, nullptr);
  }
  poursim_obs_t obs;
  poursim_observe(g.w, &obs);

  pour_can_node_config_t nc = pour_can_node_default_config();
  nc.node_id = run.node_id;
  nc.identity.tau_max_cnm = static_cast<uint16_t>(std::lround(cfg.tau_max * 100.0));
  pour_can_node_t node;
  pour_control_t ctl;
  const pour_control_config_t cc = firmware_config(cfg);
  if (pour_can_node_init(&node, &nc) != POUR_OK || pour_control_init_external(&ctl, &cc, 1u) != POUR_OK) {
    *err = "the firmware refused the node id or its config";
    return false;
  }

  AtomicFile file;
  if (!file.open(run.path, err)) return false;
  std::FILE *f = file.stream();
  pour_can_frame_t fr;
  const pour_can_experiment_start_t start = {run.kind};
  if (pour_can_pack_experiment_start(run.node_id, &start, &fr) != POUR_OK) {
    *err = "no such experiment kind";
    return false;
  }
  put_frame(f, 0, fr);
  (void)pour_can_node_receive(&node, &fr);

  const uint32_t limit = pour_experiment_duration_ms(&cc.experiment, run.kind) + kSpareTicks;
  bool ran = false, asked = false;
  uint8_t kind = 0;
  uint32_t tail = 0, tick = 0;
  pour_control_output_t o{};
  for (; tick < limit && tail < kTailTicks; ++tick) {
    const pour_can_sensors_t s = {static_cast<uint8_t>(tick & 0xFFu), obs.encoder, wire_grams(obs.scale_rotating_g),
                                  wire_grams(obs.scale_target_g)};
    if (pour_can_pack_sensors(run.node_id, &s, &fr) != POUR_OK) {
      *err = "a sensor sample outside the Sensors frame's range (encoder_bits > 24?)";
      return false;
    }
    put_frame(f, tick, fr);
    (void)pour_can_node_receive(&node, &fr);
    // The port: the start to the core before the tick, its answer after.
    if (pour_can_node_take_experiment(&node, &kind)) {
      pour_control_experiment(&ctl, kind);
      asked = true;
    }
    pour_control_input_t in;
    pour_can_node_begin_tick(&node, &in);
    (void)pour_control_update(&ctl, &in);
    pour_control_shape(&ctl, &o);
    if (asked) {
      asked = false;
      const uint8_t answer = pour_control_experiment_answer(&ctl);
      if (pour_can_node_experiment_ack(&node, kind, answer, &fr) == POUR_OK) put_frame(f, tick, fr);
      if (answer != POUR_CONTROL_EXPERIMENT_ACCEPTED) {
        *err = "the controller refused the experiment";
        return false;
      }
    }
    pour_can_frame_t tx[POUR_CAN_NODE_MAX_TX];
    const uint8_t n = pour_can_node_end_tick(&node, &o, 0u, tx);
    for (uint8_t i = 0; i < n; ++i) put_frame(f, tick, tx[i]);
    ran = ran || o.mode == POUR_MODE_RUN;
    if (ran && o.mode != POUR_MODE_RUN) ++tail;
    poursim_set_brake(g.w, o.brake ? 1 : 0);
    if (poursim_step(g.w, o.torque / 32768.0, &obs) != POURSIM_OK) {
      *err = std::string("the simulated world: ") + poursim_world_error(g.w);
      return false;
    }
  }
  if (!file.commit(err)) return false;
  out->ticks = tick;
  out->phase = o.action;
  out->mode = o.mode;
  out->faults = o.faults;
  return true;
}

} // namespace poursim
