// SPDX-License-Identifier: MIT
// poursim_record_field: each record's fields with their offsets, sizes and element types, taken from the
// compiler (offsetof, sizeof, the member's declared type) so that the table cannot disagree with the
// headers. The names are listed here once; pour.records checks that they tile each record (a member left
// out leaves a gap it refuses).
#include "poursim/record_layouts.h"

#include <cstddef>
#include <type_traits>

#include "record_kinds.hpp"

namespace {

using poursim_kinds::Kind;

template <typename M> using Elem = typename std::remove_all_extents<M>::type;
template <typename M> constexpr size_t count_of() { return std::is_array<M>::value ? std::extent<M>::value : 1; }

// One row; M is the member's declared type.
#define POURSIM_FIELD(R, f)                                                                                       \
  poursim_record_field_t {                                                                                    \
    #R, sizeof(R), alignof(R), #f, offsetof(R, f), sizeof(Elem<decltype(R::f)>), Kind<Elem<decltype(R::f)>>::name, \
        count_of<decltype(R::f)>()                                                                            \
  }
#define F(R, f) POURSIM_FIELD(R, f)

const poursim_record_field_t kTable[] = {
    // pour.sim.poursim
    F(poursim_obs_t, step), F(poursim_obs_t, t), F(poursim_obs_t, theta), F(poursim_obs_t, omega),
    F(poursim_obs_t, v_rotating), F(poursim_obs_t, v_target), F(poursim_obs_t, v_spill), F(poursim_obs_t, v_flight),
    F(poursim_obs_t, torque), F(poursim_obs_t, done), F(poursim_obs_t, motor_torque), F(poursim_obs_t, encoder),
    F(poursim_obs_t, scale_rotating_g), F(poursim_obs_t, scale_target_g), F(poursim_obs_t, drive_faults),
    F(poursim_obs_t, drive_trusted),
    F(poursim_reward_t, k_target), F(poursim_reward_t, k_spill), F(poursim_reward_t, gamma),
    F(poursim_policy_t, n_actions), F(poursim_policy_t, decision_period), F(poursim_policy_t, w),
    F(poursim_policy_t, levels), F(poursim_policy_t, theta_min), F(poursim_policy_t, theta_max),
    F(poursim_policy_t, omega_max), F(poursim_policy_t, greedy), F(poursim_policy_t, reward),
    F(poursim_policy_t, k_reversal),
    F(poursim_rollout_buffers_t, capacity), F(poursim_rollout_buffers_t, features),
    F(poursim_rollout_buffers_t, actions), F(poursim_rollout_buffers_t, rewards), F(poursim_rollout_buffers_t, probs),
    F(poursim_rollout_buffers_t, step_capacity), F(poursim_rollout_buffers_t, step_rewards),
    F(poursim_rollout_buffers_t, step_theta), F(poursim_rollout_buffers_t, step_torque),
    F(poursim_episode_t, n_steps), F(poursim_episode_t, n_decisions), F(poursim_episode_t, poured),
    F(poursim_episode_t, spilled), F(poursim_episode_t, remaining), F(poursim_episode_t, finish_time),
    F(poursim_episode_t, ret), F(poursim_episode_t, reward_sum), F(poursim_episode_t, max_theta),
    F(poursim_episode_t, liquid_l), F(poursim_episode_t, peak_omega), F(poursim_episode_t, peak_alpha),
    F(poursim_episode_t, reversals), F(poursim_episode_t, faults), F(poursim_episode_t, fault_step),
    F(poursim_retention_t, n), F(poursim_retention_t, theta), F(poursim_retention_t, kept),
    F(poursim_retention_t, ideal), F(poursim_retention_t, onset), F(poursim_retention_t, ideal_onset),
    F(poursim_retention_t, rms_gap),
    F(poursim_slosh_t, freq), F(poursim_slosh_t, freq_theory), F(poursim_slosh_t, damping),
    F(poursim_slosh_t, amplitude), F(poursim_slosh_t, noise), F(poursim_slosh_t, n),
    F(poursim_drive_check_t, latency_ticks), F(poursim_drive_check_t, inertia_measured),
    F(poursim_drive_check_t, inertia_expected), F(poursim_drive_check_t, inertia_bucket),
    F(poursim_drive_check_t, breakaway_torque), F(poursim_drive_check_t, terminal_load),
    F(poursim_drive_check_t, terminal_speed), F(poursim_drive_check_t, terminal_expected),
    F(poursim_drive_check_t, friction_speed), F(poursim_drive_check_t, friction_measured),
    F(poursim_drive_check_t, friction_expected),
    F(poursim_sensor_check_t, encoder_max_error), F(poursim_sensor_check_t, encoder_at_stop),
    F(poursim_sensor_check_t, liquid_g), F(poursim_sensor_check_t, rest_rotating_g),
    F(poursim_sensor_check_t, target_liquid_g), F(poursim_sensor_check_t, rest_target_g),
    F(poursim_sensor_check_t, update_rate_hz), F(poursim_sensor_check_t, delay_s),
    F(poursim_sensor_check_t, delay_match), F(poursim_sensor_check_t, noise_rms_g),
    F(poursim_sensor_check_t, noise_expected_g), F(poursim_sensor_check_t, impact_impulse_gs),
    F(poursim_sensor_check_t, impact_expected_gs), F(poursim_sensor_check_t, impact_peak_g),
    F(poursim_sensor_check_t, impact_peak_reading_g), F(poursim_sensor_check_t, hash_unchanged),
    // pour.policy.weights_h
    F(poursim_weights_file_t, format), F(poursim_weights_file_t, n_features), F(poursim_weights_file_t, n_actions),
    F(poursim_weights_file_t, w_frac_bits), F(poursim_weights_file_t, decision_period_ms),
    F(poursim_weights_file_t, theta_min_urad), F(poursim_weights_file_t, theta_max_urad),
    F(poursim_weights_file_t, omega_max_urad_s), F(poursim_weights_file_t, tau_max_mnm),
    F(poursim_weights_file_t, content_hash), F(poursim_weights_file_t, w), F(poursim_weights_file_t, levels),
    F(poursim_weights_file_t, has_float_reference), F(poursim_weights_file_t, w_float),
    // pour.bench.params
    F(pour_param_info_t, id), F(pour_param_info_t, name), F(pour_param_info_t, unit), F(pour_param_info_t, min),
    F(pour_param_info_t, max), F(pour_param_info_t, default_value),
    // the firmware core (pour.core)
    F(pour_sensors_t, seq), F(pour_sensors_t, encoder), F(pour_sensors_t, scale_rotating_g),
    F(pour_sensors_t, scale_target_g),
    F(pour_state_t, seq), F(pour_state_t, theta_urad), F(pour_state_t, omega_urad_s), F(pour_state_t, v_rotating),
    F(pour_state_t, v_target), F(pour_state_t, v_spill),
    F(pour_control_input_t, sensors_fresh), F(pour_control_input_t, sensors), F(pour_control_input_t, estop),
    F(pour_control_input_t, clear_faults), F(pour_control_input_t, link_fault), F(pour_control_input_t, stop),
    F(pour_control_input_t, reset), F(pour_control_input_t, drive_faults), F(pour_control_input_t, drive_trusted),
    F(pour_control_output_t, torque), F(pour_control_output_t, action), F(pour_control_output_t, probs),
    F(pour_control_output_t, mode), F(pour_control_output_t, faults), F(pour_control_output_t, limits),
    F(pour_control_output_t, tick), F(pour_control_output_t, refused), F(pour_control_output_t, brake),
    F(pour_control_output_t, power),
};

#undef F
#undef POURSIM_FIELD

} // namespace

extern "C" const poursim_record_field_t *poursim_record_field(int i) {
  const int n = static_cast<int>(sizeof kTable / sizeof kTable[0]);
  return i >= 0 && i < n ? &kTable[i] : nullptr;
}

extern "C" int poursim_record_field_info(int i, const char **record, size_t *record_size, size_t *record_align,
                                         const char **field, size_t *offset, size_t *size, const char **kind,
                                         size_t *count) {
  const poursim_record_field_t *r = poursim_record_field(i);
  if (r == nullptr) return POURSIM_EINVAL;
  if (record != nullptr) *record = r->record;
  if (record_size != nullptr) *record_size = r->record_size;
  if (record_align != nullptr) *record_align = r->record_align;
  if (field != nullptr) *field = r->field;
  if (offset != nullptr) *offset = r->offset;
  if (size != nullptr) *size = r->size;
  if (kind != nullptr) *kind = r->kind;
  if (count != nullptr) *count = r->count;
  return POURSIM_OK;
}
