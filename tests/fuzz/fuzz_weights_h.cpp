// SPDX-License-Identifier: MIT
// host_sim's weights.h loader on arbitrary text: never crashes, never reads out of bounds, and accepts
// only files the firmware core accepts too (the shape, the hash and pour_policy_weights_validate).
#include <cstring>

#include "fuzz_check.h"
#include "poursim/weights_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > (1u << 20)) return 0; // poursim_weights_load refuses larger files before parsing
  static poursim_weights_file_t wf;
  char err[POURSIM_ERR_LEN] = "";
  int rc = poursim_weights_parse(reinterpret_cast<const char *>(data), size, "fuzz.h", &wf, err, sizeof err);
  if (rc != POURSIM_OK) {
    FUZZ_CHECK(rc < 0 && std::strncmp(err, "fuzz.h:", 7) == 0, "rc %d, message '%s'", rc, err);
    return 0;
  }
  FUZZ_CHECK(wf.n_actions >= POUR_POLICY_MIN_ACTIONS && wf.n_actions <= POUR_POLICY_MAX_ACTIONS, "n %d", wf.n_actions);
  for (int i = 1; i < wf.n_actions; ++i) FUZZ_CHECK(wf.levels[i] > wf.levels[i - 1], "levels at %d", i);
  pour_policy_weights_t view;
  poursim_weights_view(&wf, &view);
  FUZZ_CHECK(pour_policy_weights_validate(&view) == POUR_OK, "the core refuses an accepted file");
  return 0;
}
