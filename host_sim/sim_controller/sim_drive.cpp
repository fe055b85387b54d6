// SPDX-License-Identifier: MIT
extern "C" { // the C headers carry no linkage of their own
#include "calibration_flow.h"
#include "sim_drive.h"
}

#include <cstdio>
#include <cstring>

#include "foc_drive.hpp"

namespace {

// The empty bucket on its bearing, as tests/sim/test_calibration.cpp closes the loop: a rigid inertia with
// viscous friction at the output, stopped dead while the brake is engaged.
constexpr double kInertia = 0.038; // [kg·m²]
constexpr double kFriction = 2.0;  // [N·m·s/rad]

struct SimDrive {
  poursim::FocDrive foc;
  pour_calibration_flow_t flow{};
  uint32_t regs[POUR_FLASH_N_REGS] = {};
  uint32_t page[POUR_FLASH_PAGE_BYTES / 4] = {};
  pour_flash_t flash{};
  double omega = 0.0; // output speed [rad/s]
};

SimDrive g_sim; // one drive per process

} // namespace

extern "C" int pour_sim_drive_open(pour_can_node_t *node) {
  poursim_config_t c = poursim_default_config();
  c.drive = 1;
  g_sim.foc.reset(c, 1u);
  if (!g_sim.foc.running()) {
    std::fprintf(stderr, "pour_controller_sim: drive=sim: the simulated drive did not start (faults 0x%04x)\n",
                 static_cast<unsigned>(g_sim.foc.drive().faults));
    return -1;
  }
  std::memset(g_sim.page, 0xFF, sizeof g_sim.page); // erased: nothing stored
  g_sim.flash.regs = g_sim.regs;
  g_sim.flash.page = g_sim.page;
  g_sim.flash.page_number = POUR_FLASH_CAL_PAGE;
  g_sim.flash.busy_polls = 10u;
  pour_calibration_flow_init(&g_sim.flow, POUR_CAL_EMPTY, nullptr);
  pour_can_calibration_result_t r;
  pour_calibration_can_result(POUR_CAL_EMPTY, nullptr, POUR_CAN_CAL_EMPTY, &r);
  pour_can_node_set_calibration(node, &r);
  node->config.can_calibrate = true;
  return 0;
}

extern "C" bool pour_sim_drive_tick(pour_can_node_t *node, uint8_t mode) {
  const bool measuring = pour_calibration_flow_tick(&g_sim.flow, node, &g_sim.foc.drive(), mode, &g_sim.flash);
  if (!measuring) {
    g_sim.omega = 0.0;
    return false;
  }
  const double ts = 1.0 / g_sim.foc.firmware_config().pwm_hz;
  const long periods = static_cast<long>(1e-3 / ts + 0.5);
  for (long k = 0; k < periods; ++k) {
    const double tau = g_sim.foc.period(g_sim.omega);
    g_sim.omega = g_sim.foc.output().brake != 0 ? 0.0 : g_sim.omega + ts * (tau - kFriction * g_sim.omega) / kInertia;
  }
  return true;
}
