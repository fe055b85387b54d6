/* SPDX-License-Identifier: MIT */
#include "pour/commands.h"

#include <stddef.h>

void pour_commands_init(pour_commands_t *c) {
  const pour_commands_t none = {0u, false, false, false, false, 0u};
  *c = none;
}

static void drop_clear(pour_commands_t *c) {
  if (c->clear) {
    c->clear = false;
    if (c->clears_dropped != UINT32_MAX) {
      c->clears_dropped++;
    }
  }
}

void pour_commands_estop(pour_commands_t *c, uint8_t source, bool asserted) {
  c->estop_sources = (uint8_t)(asserted ? (c->estop_sources | source) : (c->estop_sources & ~source));
  if (asserted) {
    c->estop_seen = true;
    drop_clear(c); /* the clear came before this assert: it does not outlive it */
  }
}

void pour_commands_clear(pour_commands_t *c) {
  c->clear = true;
  if (c->estop_sources != 0u) {
    drop_clear(c);
  }
}

void pour_commands_stop(pour_commands_t *c) { c->stop = true; }

void pour_commands_reset(pour_commands_t *c) { c->reset = true; }

void pour_commands_take(pour_commands_t *c, pour_control_input_t *in) {
  const bool level = c->estop_sources != 0u;
  in->estop = level || c->estop_seen;
  /* An e-stop asserted in this tick's collection wins over a clear that came after its release: the core
   * sees the assert this tick, and the clear would be ignored there; it is dropped here so that it cannot
   * count in the next tick either. */
  if (c->estop_seen && !level) {
    drop_clear(c);
  }
  in->clear_faults = c->clear;
  in->stop = c->stop;
  in->reset = c->reset;
  c->estop_seen = false;
  c->clear = false;
  c->stop = false;
  c->reset = false;
}
