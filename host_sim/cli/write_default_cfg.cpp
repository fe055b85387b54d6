// SPDX-License-Identifier: MIT
// Writes the simulator's defaults as a config file (configs/sim/default.cfg is its output):
// write_default_cfg OUT. Exit status 0 on success, 2 with a message on a bad argument or a failed write.
#include <cstdio>

#include "poursim/poursim.h"

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_default_cfg OUT (writes every config key with its default)\n");
    return 2;
  }
  const poursim_config_t defaults = poursim_default_config();
  char err[POURSIM_ERR_LEN];
  if (poursim_config_write(&defaults, argv[1], err, sizeof err) != POURSIM_OK) {
    std::fprintf(stderr, "write_default_cfg: %s\n", err);
    return 2;
  }
  return 0;
}
