// SPDX-License-Identifier: MIT
// poursim_function_info: each function a binding calls, with its return and parameter kinds taken from its
// declaration (decltype of the function), so that the table cannot disagree with the headers. The names are
// listed here once; a parameter type the kinds do not name fails the build.
#include "poursim/function_table.h"

#include <string>
#include <type_traits>
#include <vector>

#include "record_kinds.hpp"
extern "C" {
#include "pour/faults.h"
#include "pour/fixed.h"
}
#include "poursim/core.h"
#include "poursim/record_layouts.h"
#include "poursim/stepper.h"

namespace {

using poursim_kinds::Kind;

template <typename T, typename = void> struct HasKind : std::false_type {};
template <typename T> struct HasKind<T, std::void_t<decltype(Kind<T>::name)>> : std::true_type {};
template <typename> constexpr bool kNoKind = false;

template <typename T> std::string kind_of() {
  if constexpr (std::is_void_v<T>) {
    return "void";
  } else if constexpr (HasKind<T>::value) {
    return Kind<T>::name;
  } else if constexpr (std::is_enum_v<T>) {
    return kind_of<std::underlying_type_t<T>>();
  } else if constexpr (std::is_pointer_v<T>) {
    using P = std::remove_cv_t<std::remove_pointer_t<T>>;
    if constexpr (std::is_same_v<P, char>) {
      return "cstr"; // a buffer the callee writes a NUL-terminated text into
    } else if constexpr (std::is_void_v<P> || (std::is_class_v<P> && !HasKind<P>::value)) {
      return "ptr";
    } else {
      return kind_of<P>() + "*";
    }
  } else {
    static_assert(kNoKind<T>, "a parameter or return type with no kind: name it in record_kinds.hpp");
    return "";
  }
}

struct Row {
  const char *name;
  std::string returns, params;
};

template <typename R, typename... A> Row row(const char *name, R (*)(A...)) {
  std::string params;
  ((params += (params.empty() ? "" : ",") + kind_of<A>()), ...);
  return Row{name, kind_of<R>(), params};
}

#define FN(f) row(#f, &f)

const std::vector<Row> &table() {
  static const std::vector<Row> rows = {
      // pour.sim.poursim
      FN(poursim_config_new), FN(poursim_config_free), FN(poursim_config_key), FN(poursim_config_key_info),
      FN(poursim_config_get), FN(poursim_config_validate), FN(poursim_config_load), FN(poursim_config_set),
      FN(poursim_config_write), FN(poursim_create), FN(poursim_reset), FN(poursim_step), FN(poursim_step_servo),
      FN(poursim_set_brake), FN(poursim_world_error), FN(poursim_max_density_ratio), FN(poursim_measure_retention),
      FN(poursim_measure_slosh), FN(poursim_ideal_retained), FN(poursim_observe), FN(poursim_episode_config),
      FN(poursim_measure_drive), FN(poursim_measure_sensors), FN(poursim_destroy), FN(poursim_particle_count), FN(poursim_particles),
      FN(poursim_particle_regions), FN(poursim_max_overlap), FN(poursim_max_wall_penetration),
      FN(poursim_trajectory_hash), FN(poursim_rollout), FN(poursim_version), FN(poursim_sizeof),
      FN(poursim_default_reward), FN(poursim_reward_validate), FN(poursim_features), FN(poursim_fraction_to_q15),
      FN(poursim_stepper_create), FN(poursim_stepper_destroy), FN(poursim_stepper_reset),
      FN(poursim_stepper_advance), FN(poursim_stepper_obs), FN(poursim_stepper_state), FN(poursim_stepper_faults),
      FN(poursim_stepper_episode),
      // pour.policy.weights_h, pour.bench.params, pour.libpoursim
      FN(poursim_weights_parse), FN(poursim_weights_load), FN(pour_param_info), FN(pour_fault_name),
      FN(pour_mode_name),
      // the firmware core (pour.core)
      FN(pour_status_name), FN(pour_sensors_theta_urad), FN(poursim_fw_config_size), FN(poursim_fw_config_init),
      FN(poursim_fw_config_field), FN(poursim_fw_config_set), FN(poursim_fw_config_get),
      FN(poursim_envelope_create), FN(poursim_envelope_destroy), FN(poursim_envelope_apply),
      FN(poursim_envelope_force), FN(poursim_envelope_active), FN(poursim_envelope_torque),
      FN(poursim_envelope_band), FN(poursim_estimator_create), FN(poursim_estimator_destroy),
      FN(poursim_estimator_reset), FN(poursim_estimator_update), FN(poursim_core_create), FN(poursim_core_destroy),
      FN(poursim_core_update), FN(poursim_core_state), FN(poursim_core_decide), FN(poursim_core_request),
      FN(poursim_core_shape), FN(poursim_core_step),
  };
  return rows;
}

#undef FN

} // namespace

extern "C" int poursim_function_info(int i, const char **name, const char **returns, const char **params) {
  const std::vector<Row> &rows = table();
  if (i < 0 || i >= static_cast<int>(rows.size())) return POURSIM_EINVAL;
  const Row &r = rows[static_cast<size_t>(i)];
  if (name != nullptr) *name = r.name;
  if (returns != nullptr) *returns = r.returns.c_str();
  if (params != nullptr) *params = r.params.c_str();
  return POURSIM_OK;
}
