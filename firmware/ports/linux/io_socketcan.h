/* SPDX-License-Identifier: MIT */
/* SocketCAN transport for the controller: the pour CAN protocol (can/pour.dbc) on a Linux CAN interface.
 * Sensors, Estop, Stop, ClearErrors and Reset in; Torque (one per answered state), Heartbeat and
 * Identity out. Every frame, the command watchdog and the control input of a tick are pour::can's node
 * (the same calls as the Cortex-M4 port); this file only moves frames and keeps the wall clock. */
#ifndef POUR_LINUX_IO_SOCKETCAN_H
#define POUR_LINUX_IO_SOCKETCAN_H

#include <stdbool.h>
#include <stdint.h>

#include "io.h"
#include "pour/can_node.h"
#include "pour/params.h"

typedef struct {
  char iface[16];                /* interface name, e.g. "vcan0" (IFNAMSIZ) */
  pour_can_node_config_t node;   /* node id, watchdog [ms], heartbeat period [ms], identity */
  uint32_t watchdog_grace_ms;    /* added to the watchdog (lockstep: the loop's stall time) [ms] */
  char params_path[256];         /* parameter file ("": parameters in memory only, save refused) */
  pour_params_t params;          /* the parameters at start (pour_io_socketcan_load_params) */
  bool sim_drive;                /* drive=sim: the caller attaches a drive of the port's own below */
  /* A drive of the port's own, or NULL (a CalibrationStart is then answered UNAVAILABLE): drive_open is
   * called once the node exists (0, or -1: the transport does not open), drive_tick once a tick before the
   * core's step with the mode of the latest step (sim_drive.h). */
  int (*drive_open)(pour_can_node_t *node);
  bool (*drive_tick)(pour_can_node_t *node, uint8_t mode);
} pour_io_socketcan_config_t;

/* Parses "IFACE[,node=N][,heartbeat-ms=N][,watchdog-ms=N][,params=FILE][,drive=sim]" onto *config (whose other fields
 * keep their values). Returns 0, or -1 with a message naming the bad part on stderr. */
int pour_io_socketcan_parse(const char *spec, pour_io_socketcan_config_t *config);

/* The parameters at start: the defaults (control as given, the parsed node id), then the parameter file if
 * there is one, checked by the core with weights; *control and the node id take their values. Returns 0, or -1 with a message on stderr (a
 * corrupt or refused file: the controller does not start on it). */
int pour_io_socketcan_load_params(pour_io_socketcan_config_t *config, pour_control_config_t *control,
                                  const pour_policy_weights_t *weights);

/* Opens a CAN_RAW socket on the interface, filtered to the node's ids. Returns 0, or -1 with a message
 * on stderr (no such interface, no CAN support in the kernel, ...). */
int pour_io_socketcan_open(pour_io_t *io, const pour_io_socketcan_config_t *config);

#endif /* POUR_LINUX_IO_SOCKETCAN_H */
