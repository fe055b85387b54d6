// SPDX-License-Identifier: MIT
// The LCM message types our C and C++ programs decode (sensor_sample_t and command_t: the controller and the
// CAN bridge, in C; torque_t: host_sim, in C++), decoded from arbitrary bytes by the generated C and C++
// code: no crash, no out-of-bounds read; both decoders agree on what they consume; and a buffer decoded
// exactly re-encodes to the same bytes in both languages. particles_t, plant_truth_t and controller_status_t
// are decoded only by the Python and Java tools; the generated C and C++ decoders of particles_t allocate whatever
// length a message claims (a negative n asks for ~16 GB), which is why no C or C++ code may decode it.
#include <cstring>
#include <vector>

#include "fuzz_check.h"
#include "pour/command_t.hpp"
#include "pour/sensor_sample_t.hpp"
#include "pour/torque_t.hpp"

extern "C" {
#include "pour_command_t.h"
#include "pour_sensor_sample_t.h"
#include "pour_torque_t.h"
}

namespace {

// CMsg: the C struct; its decode/encode/cleanup functions; Cpp: the C++ class.
template <class CMsg, class Cpp>
void check(const uint8_t *data, int size, int (*c_decode)(const void *, int, int, CMsg *),
           int (*c_encode)(void *, int, int, const CMsg *), int (*c_cleanup)(CMsg *), const char *name) {
  CMsg c;
  std::memset(&c, 0, sizeof c);
  const int nc = c_decode(data, 0, size, &c);
  Cpp cpp;
  const int ncpp = cpp.decode(data, 0, size);
  FUZZ_CHECK((nc < 0) == (ncpp < 0) && (nc < 0 || nc == ncpp), "%s: C decodes %d bytes, C++ %d", name, nc, ncpp);
  if (nc >= 0 && nc == size) { // what the handlers accept: an exact, complete message
    std::vector<uint8_t> a(static_cast<size_t>(size)), b(static_cast<size_t>(size));
    FUZZ_CHECK(c_encode(a.data(), 0, size, &c) == size, "%s: C re-encode", name);
    FUZZ_CHECK(cpp.encode(b.data(), 0, size) == size, "%s: C++ re-encode", name);
    FUZZ_CHECK(std::memcmp(a.data(), data, a.size()) == 0 && a == b, "%s: re-encoding changed the bytes", name);
  }
  if (nc >= 0) c_cleanup(&c);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > (1u << 16)) return 0;
  const int n = static_cast<int>(size);
  check<pour_sensor_sample_t, pour::sensor_sample_t>(data, n, pour_sensor_sample_t_decode, pour_sensor_sample_t_encode,
                                                     pour_sensor_sample_t_decode_cleanup, "sensor_sample_t");
  check<pour_torque_t, pour::torque_t>(data, n, pour_torque_t_decode, pour_torque_t_encode,
                                       pour_torque_t_decode_cleanup, "torque_t");
  check<pour_command_t, pour::command_t>(data, n, pour_command_t_decode, pour_command_t_encode,
                                         pour_command_t_decode_cleanup, "command_t");

  return 0;
}
