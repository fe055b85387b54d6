// SPDX-License-Identifier: MIT
// The simulator's config loader on arbitrary files (through a memfd, so the real path-reading code
// runs): never crashes, names the file and a line in every refusal, and what it accepts validates.
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>

#include "fuzz_check.h"
#include "poursim/poursim.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static int fd = memfd_create("fuzz.cfg", 0);
  static char path[64];
  if (path[0] == '\0') std::snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
  FUZZ_CHECK(fd >= 0 && ftruncate(fd, 0) == 0 && pwrite(fd, data, size, 0) == static_cast<ssize_t>(size), "memfd");
  poursim_config_t cfg = poursim_default_config();
  char err[POURSIM_ERR_LEN] = "";
  int rc = poursim_config_load(path, &cfg, err, sizeof err);
  if (rc != POURSIM_OK) {
    FUZZ_CHECK(rc < 0 && std::strncmp(err, path, std::strlen(path)) == 0, "rc %d, message '%s'", rc, err);
    return 0;
  }
  FUZZ_CHECK(poursim_config_validate(&cfg, err, sizeof err) == POURSIM_OK, "accepted but invalid: %s", err);
  return 0;
}
