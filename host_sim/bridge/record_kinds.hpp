// SPDX-License-Identifier: MIT
// The names libpoursim's tables give C types: "i8" ... "u64", "f32", "f64", "bool", "cstr" (a NUL-terminated
// const char *) for a scalar, a record's own C name for a record of the record table. Shared by the record
// table (record_layouts.cpp) and the function table (function_table.cpp); a type with no name here fails the
// build where a table uses it.
#ifndef POURSIM_RECORD_KINDS_HPP
#define POURSIM_RECORD_KINDS_HPP

#include <cstdint>

extern "C" {
#include "pour/control.h"
#include "pour/obs.h"
#include "pour/params.h"
#include "pour/sensors.h"
}
#include "poursim/checks.h"
#include "poursim/poursim.h"
#include "poursim/weights_file.h"

namespace poursim_kinds {

template <typename T, typename = void> struct Kind;
template <> struct Kind<int8_t> { static constexpr const char *name = "i8"; };
template <> struct Kind<uint8_t> { static constexpr const char *name = "u8"; };
template <> struct Kind<int16_t> { static constexpr const char *name = "i16"; };
template <> struct Kind<uint16_t> { static constexpr const char *name = "u16"; };
template <> struct Kind<int32_t> { static constexpr const char *name = "i32"; };
template <> struct Kind<uint32_t> { static constexpr const char *name = "u32"; };
template <> struct Kind<int64_t> { static constexpr const char *name = "i64"; };
template <> struct Kind<uint64_t> { static constexpr const char *name = "u64"; };
template <> struct Kind<float> { static constexpr const char *name = "f32"; };
template <> struct Kind<double> { static constexpr const char *name = "f64"; };
template <> struct Kind<bool> { static constexpr const char *name = "bool"; };
template <> struct Kind<const char *> { static constexpr const char *name = "cstr"; };
template <> struct Kind<double *> { static constexpr const char *name = "f64*"; };
template <> struct Kind<const double *> { static constexpr const char *name = "f64*"; };
template <> struct Kind<int32_t *> { static constexpr const char *name = "i32*"; };

// The records of the record table, by their C names.
#define POURSIM_RECORD_KIND(R)                                                                                   \
  template <> struct Kind<R> { static constexpr const char *name = #R; }
POURSIM_RECORD_KIND(poursim_obs_t);
POURSIM_RECORD_KIND(poursim_reward_t);
POURSIM_RECORD_KIND(poursim_policy_t);
POURSIM_RECORD_KIND(poursim_rollout_buffers_t);
POURSIM_RECORD_KIND(poursim_episode_t);
POURSIM_RECORD_KIND(poursim_retention_t);
POURSIM_RECORD_KIND(poursim_slosh_t);
POURSIM_RECORD_KIND(poursim_drive_check_t);
POURSIM_RECORD_KIND(poursim_sensor_check_t);
POURSIM_RECORD_KIND(poursim_weights_file_t);
POURSIM_RECORD_KIND(pour_param_info_t);
POURSIM_RECORD_KIND(pour_sensors_t);
POURSIM_RECORD_KIND(pour_state_t);
POURSIM_RECORD_KIND(pour_control_input_t);
POURSIM_RECORD_KIND(pour_control_output_t);
#undef POURSIM_RECORD_KIND

} // namespace poursim_kinds

#endif // POURSIM_RECORD_KINDS_HPP
