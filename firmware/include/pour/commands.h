/* SPDX-License-Identifier: MIT */
/* The host's commands as they arrive between two ticks, reduced to what one tick of the core acts on, with
 * their order inside the tick kept where it matters: the e-stop level is sampled at every frame, and a
 * clear counts only if the e-stop was released before it and stays released until the tick. Transports
 * (the CAN node, the Linux port's LCM link) feed it frame by frame; nothing else decides that order.
 * The e-stop has sources (the bus's frames, a hardwired line): it is asserted while any source asserts it. */
#ifndef POUR_COMMANDS_H
#define POUR_COMMANDS_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/control.h"

/* The e-stop's sources, as bits of pour_commands_t.estop_sources. */
#define POUR_ESTOP_BUS 0x01u  /* Estop frames (CAN) or command messages (LCM) */
#define POUR_ESTOP_LINE 0x02u /* the hardwired input, sampled by the port */

typedef struct {
  uint8_t estop_sources; /* POUR_ESTOP_* bits asserting now (the latest level of each) */
  bool estop_seen;   /* asserted at some frame since the last tick (a pulse is not lost) */
  bool clear;        /* a clear that still counts */
  bool stop;         /* one-shot */
  bool reset;        /* one-shot */
  uint32_t clears_dropped; /* clears that arrived with the e-stop held, or were followed by an assert [count] */
} pour_commands_t;

/* Nothing pending, e-stop released. */
void pour_commands_init(pour_commands_t *c);

/* An e-stop level of one source (POUR_ESTOP_BUS or POUR_ESTOP_LINE), as a frame or a sample of the line
 * reports it. An assert also drops a clear received before it in the same tick. */
void pour_commands_estop(pour_commands_t *c, uint8_t source, bool asserted);
/* A clear request: dropped (and counted) while the e-stop is held. */
void pour_commands_clear(pour_commands_t *c);
void pour_commands_stop(pour_commands_t *c);
void pour_commands_reset(pour_commands_t *c);

/* Start of a tick: writes in->estop (asserted if it was at any frame since the last tick), clear_faults,
 * stop and reset, then starts the next tick's collection (the level stays). */
void pour_commands_take(pour_commands_t *c, pour_control_input_t *in);

#endif /* POUR_COMMANDS_H */
