// SPDX-License-Identifier: MIT
// poursim/core.h: the firmware core behind handles, its config behind a field table.
#include "poursim/core.h"

#include <cstring>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>

#include "controllers.hpp"
#include "poursim/checks.h"
#include "poursim_internal.hpp"

using poursim::set_error;

namespace {

struct Field {
  const char *name;
  size_t offset;
  size_t size;
  bool is_signed;
};

// Enums have an underlying type, the integers are their own.
template <typename T, bool = std::is_enum<T>::value> struct Underlying { using type = std::underlying_type_t<T>; };
template <typename T> struct Underlying<T, false> { using type = T; };

#define POURSIM_FW_FIELD(path)                                                                                   \
  Field {                                                                                                      \
    #path, offsetof(pour_control_config_t, path), sizeof(std::declval<pour_control_config_t>().path),           \
        std::is_signed<typename Underlying<                                                                    \
            std::remove_reference_t<decltype(std::declval<pour_control_config_t>().path)>>::type>::value        \
  }

// Every field of pour_control_config_t (control.h and the configs it holds), by its C path.
const Field kFields[] = {
    POURSIM_FW_FIELD(safety.tau_limit), POURSIM_FW_FIELD(safety.slew_per_tick),
    POURSIM_FW_FIELD(safety.theta_min_urad), POURSIM_FW_FIELD(safety.theta_max_urad),
    POURSIM_FW_FIELD(safety.omega_max_urad_s), POURSIM_FW_FIELD(safety.alpha_max_urad_s2),
    POURSIM_FW_FIELD(safety.omega_slack_urad_s), POURSIM_FW_FIELD(safety.governor_gain),
    POURSIM_FW_FIELD(safety.knee_theta_urad), POURSIM_FW_FIELD(safety.slow_omega_urad_s),
    POURSIM_FW_FIELD(safety.knee_decel_urad_s2), POURSIM_FW_FIELD(safety.slow_torque_ff),
    POURSIM_FW_FIELD(safety.slow_ki_per_s),
    POURSIM_FW_FIELD(sensors.encoder_bits), POURSIM_FW_FIELD(sensors.bandwidth_rad_s),
    POURSIM_FW_FIELD(sensors.scale_min_g), POURSIM_FW_FIELD(sensors.scale_max_g),
    POURSIM_FW_FIELD(sensors.mass_min_g), POURSIM_FW_FIELD(sensors.jump_max_urad),
    POURSIM_FW_FIELD(input_timeout_ms), POURSIM_FW_FIELD(safe_torque), POURSIM_FW_FIELD(policy_mode),
    POURSIM_FW_FIELD(seed), POURSIM_FW_FIELD(plausible_theta_urad), POURSIM_FW_FIELD(plausible_omega_urad_s),
    POURSIM_FW_FIELD(plausible_volume_sum), POURSIM_FW_FIELD(supervisor.checks),
    POURSIM_FW_FIELD(supervisor.theta_margin_urad), POURSIM_FW_FIELD(supervisor.omega_max_urad_s),
    POURSIM_FW_FIELD(supervisor.window_ms), POURSIM_FW_FIELD(supervisor.torque_min),
    POURSIM_FW_FIELD(supervisor.omega_against_urad_s), POURSIM_FW_FIELD(supervisor.against_ms),
    POURSIM_FW_FIELD(supervisor.encoder_move_urad), POURSIM_FW_FIELD(supervisor.encoder_ms),
    POURSIM_FW_FIELD(supervisor.volume_step_max), POURSIM_FW_FIELD(supervisor.accel_full_urad_s2),
    POURSIM_FW_FIELD(supervisor.accel_passive_urad_s2), POURSIM_FW_FIELD(stop.torque_max),
    POURSIM_FW_FIELD(stop.return_speed_urad_s), POURSIM_FW_FIELD(stop.return_gain_per_s),
    POURSIM_FW_FIELD(stop.gain), POURSIM_FW_FIELD(stop.rest_theta_urad),
    POURSIM_FW_FIELD(stop.rest_omega_urad_s), POURSIM_FW_FIELD(stop.timeout_ms),
    POURSIM_FW_FIELD(restart_jump_max_urad), POURSIM_FW_FIELD(experiment.hold_theta_urad),
    POURSIM_FW_FIELD(experiment.range_urad), POURSIM_FW_FIELD(experiment.kp_per_rad),
    POURSIM_FW_FIELD(experiment.kd_per_rad_s), POURSIM_FW_FIELD(experiment.step_torque),
    POURSIM_FW_FIELD(experiment.chirp_torque), POURSIM_FW_FIELD(experiment.prbs_torque),
    POURSIM_FW_FIELD(experiment.prbs_bit_ms), POURSIM_FW_FIELD(experiment.chirp_f0_mhz),
    POURSIM_FW_FIELD(experiment.chirp_f1_mhz), POURSIM_FW_FIELD(experiment.tilt_theta_urad),
    POURSIM_FW_FIELD(experiment.tilt_speed_urad_s), POURSIM_FW_FIELD(experiment.tilt_margin_urad),
    POURSIM_FW_FIELD(experiment.tilt_kp_per_rad), POURSIM_FW_FIELD(experiment.tilt_kd_per_rad_s),
};
#undef POURSIM_FW_FIELD

const Field *find_field(const char *name) {
  if (name == nullptr) return nullptr;
  for (const Field &f : kFields)
    if (std::strcmp(f.name, name) == 0) return &f;
  return nullptr;
}

const pour_control_config_t &as_config(const void *config) { return *static_cast<const pour_control_config_t *>(config); }

struct Record {
  const char *name;
  size_t size;
};
const Record kRecords[] = {
    {"pour_sensors_t", sizeof(pour_sensors_t)},
    {"pour_state_t", sizeof(pour_state_t)},
    {"pour_control_input_t", sizeof(pour_control_input_t)},
    {"pour_control_output_t", sizeof(pour_control_output_t)},
    {"poursim_obs_t", sizeof(poursim_obs_t)},
    {"poursim_reward_t", sizeof(poursim_reward_t)},
    {"poursim_policy_t", sizeof(poursim_policy_t)},
    {"poursim_rollout_buffers_t", sizeof(poursim_rollout_buffers_t)},
    {"poursim_episode_t", sizeof(poursim_episode_t)},
    {"poursim_retention_t", sizeof(poursim_retention_t)},
    {"poursim_slosh_t", sizeof(poursim_slosh_t)},
    {"poursim_drive_check_t", sizeof(poursim_drive_check_t)},
    {"poursim_sensor_check_t", sizeof(poursim_sensor_check_t)},
    {"poursim_weights_file_t", sizeof(poursim_weights_file_t)},
};

} // namespace

struct poursim_envelope {
  pour_safety_t s;
};
struct poursim_estimator {
  pour_estimator_t s;
};
struct poursim_core {
  pour_control_t ctl;
  int16_t w[POUR_POLICY_N_FEATURES * POUR_POLICY_MAX_ACTIONS];
  q15_t levels[POUR_POLICY_MAX_ACTIONS];
  pour_policy_weights_t weights;
};

namespace {

// A new handle H whose state init sets up from the config; NULL with the reason in err (the core's status
// name when it refuses).
template <typename H, typename Init>
H *create_handle(const void *config, const char *what, char *err, size_t err_len, Init init) {
  if (config == nullptr) {
    set_error(err, err_len, POURSIM_EINVAL, "%s: config is NULL", what);
    return nullptr;
  }
  auto *h = new (std::nothrow) H;
  if (h == nullptr) {
    set_error(err, err_len, POURSIM_ESTATE, "%s: out of memory", what);
    return nullptr;
  }
  const pour_status_t st = init(h, as_config(config));
  if (st != POUR_OK) {
    set_error(err, err_len, POURSIM_EINVAL, "%s refused the config: %s", what, pour_status_name(st));
    delete h;
    return nullptr;
  }
  return h;
}

} // namespace

extern "C" size_t poursim_sizeof(const char *type_name) {
  if (type_name == nullptr) return 0;
  for (const Record &r : kRecords)
    if (std::strcmp(r.name, type_name) == 0) return r.size;
  return 0;
}

extern "C" size_t poursim_fw_config_size(void) { return sizeof(pour_control_config_t); }

extern "C" void poursim_fw_config_init(void *config, const poursim_config_t *rig) {
  if (config == nullptr) return;
  const pour_control_config_t c = rig != nullptr ? poursim::firmware_config(*rig) : pour_control_default_config();
  std::memcpy(config, &c, sizeof c);
}

extern "C" const char *poursim_fw_config_field(int i) {
  const int n = static_cast<int>(sizeof kFields / sizeof kFields[0]);
  return i >= 0 && i < n ? kFields[i].name : nullptr;
}

extern "C" int poursim_fw_config_set(void *config, const char *name, int64_t value) {
  const Field *f = find_field(name);
  if (config == nullptr || f == nullptr) return POURSIM_EINVAL;
  const int bits = static_cast<int>(8 * f->size);
  const int64_t lo = f->is_signed ? -(INT64_C(1) << (bits - 1)) : 0;
  const int64_t hi = f->is_signed ? (INT64_C(1) << (bits - 1)) - 1 : (bits == 64 ? INT64_MAX : (INT64_C(1) << bits) - 1);
  if (value < lo || value > hi) return POURSIM_EINVAL;
  unsigned char *p = static_cast<unsigned char *>(config) + f->offset;
  // Little-endian hosts only (libpoursim runs on x86-64 and arm64 Linux): the low bytes of the value.
  const uint64_t u = static_cast<uint64_t>(value);
  for (size_t k = 0; k < f->size; ++k) p[k] = static_cast<unsigned char>(u >> (8 * k));
  return POURSIM_OK;
}

extern "C" int poursim_fw_config_get(const void *config, const char *name, int64_t *value) {
  const Field *f = find_field(name);
  if (config == nullptr || f == nullptr || value == nullptr) return POURSIM_EINVAL;
  const unsigned char *p = static_cast<const unsigned char *>(config) + f->offset;
  uint64_t u = 0;
  for (size_t k = 0; k < f->size; ++k) u |= static_cast<uint64_t>(p[k]) << (8 * k);
  const int bits = static_cast<int>(8 * f->size);
  if (f->is_signed && bits < 64 && (u >> (bits - 1)) != 0u) u |= ~UINT64_C(0) << bits; // sign-extend
  *value = static_cast<int64_t>(u);
  return POURSIM_OK;
}

extern "C" poursim_envelope_t *poursim_envelope_create(const void *config, char *err, size_t err_len) {
  return create_handle<poursim_envelope>(config, "pour_safety_init", err, err_len,
                                         [](poursim_envelope *h, const pour_control_config_t &c) {
                                           return pour_safety_init(&h->s, &c.safety);
                                         });
}
extern "C" void poursim_envelope_destroy(poursim_envelope_t *env) { delete env; }
extern "C" int16_t poursim_envelope_apply(poursim_envelope_t *env, int16_t requested, int32_t theta_urad,
                                          int32_t omega_urad_s) {
  return pour_safety_apply(&env->s, requested, theta_urad, omega_urad_s);
}
extern "C" void poursim_envelope_force(poursim_envelope_t *env, int16_t torque) { pour_safety_force(&env->s, torque); }
extern "C" uint8_t poursim_envelope_active(const poursim_envelope_t *env) { return env->s.active; }
extern "C" int16_t poursim_envelope_torque(const poursim_envelope_t *env) { return env->s.torque; }
extern "C" void poursim_envelope_band(const poursim_envelope_t *env, int32_t *floor_urad_s, int32_t *ceiling_urad_s) {
  *floor_urad_s = env->s.floor_urad_s;
  *ceiling_urad_s = env->s.ceiling_urad_s;
}

extern "C" poursim_estimator_t *poursim_estimator_create(const void *config, char *err, size_t err_len) {
  return create_handle<poursim_estimator>(config, "pour_estimator_init", err, err_len,
                                          [](poursim_estimator *h, const pour_control_config_t &c) {
                                            return pour_estimator_init(&h->s, &c.sensors);
                                          });
}
extern "C" void poursim_estimator_destroy(poursim_estimator_t *est) { delete est; }
extern "C" void poursim_estimator_reset(poursim_estimator_t *est) { pour_estimator_reset(&est->s); }
extern "C" int poursim_estimator_update(poursim_estimator_t *est, const pour_sensors_t *sample, pour_state_t *state) {
  return pour_estimator_update(&est->s, sample, state) ? 1 : 0;
}

extern "C" poursim_core_t *poursim_core_create(const void *config, int n_actions, int w_frac_bits,
                                               int decision_period_ms, const int16_t *w, const int16_t *levels,
                                               int32_t theta_min_urad, int32_t theta_max_urad,
                                               int32_t omega_max_urad_s, int32_t tau_max_mnm, uint32_t content_hash,
                                               char *err, size_t err_len) {
  if (config == nullptr || n_actions < 0 || n_actions > static_cast<int>(POUR_POLICY_MAX_ACTIONS) ||
      decision_period_ms < 1 || decision_period_ms > UINT16_MAX || w_frac_bits < 0 || w_frac_bits > UINT8_MAX ||
      (n_actions > 0 && (w == nullptr || levels == nullptr))) {
    set_error(err, err_len, POURSIM_EINVAL,
              "core: want a config, n_actions 0..%u (0: decisions from outside), decision_period_ms 1..65535 "
              "and, with a policy, its W and levels",
              static_cast<unsigned>(POUR_POLICY_MAX_ACTIONS));
    return nullptr;
  }
  const char *what = n_actions == 0 ? "pour_control_init_external" : "pour_control_init";
  return create_handle<poursim_core>(config, what, err, err_len, [&](poursim_core *core, const pour_control_config_t &c) {
    if (n_actions == 0) return pour_control_init_external(&core->ctl, &c, static_cast<uint16_t>(decision_period_ms));
    const size_t nw = static_cast<size_t>(POUR_POLICY_N_FEATURES) * static_cast<size_t>(n_actions);
    std::memcpy(core->w, w, nw * sizeof w[0]);
    std::memcpy(core->levels, levels, static_cast<size_t>(n_actions) * sizeof levels[0]);
    pour_policy_weights_t &v = core->weights;
    v.n_actions = static_cast<uint8_t>(n_actions);
    v.w_frac_bits = static_cast<uint8_t>(w_frac_bits);
    v.decision_period_ms = static_cast<uint16_t>(decision_period_ms);
    v.w = core->w;
    v.action_levels = core->levels;
    v.norm = pour_obs_norm_t{theta_min_urad, theta_max_urad, omega_max_urad_s};
    v.tau_max_mnm = tau_max_mnm;
    v.content_hash = content_hash;
    return pour_control_init(&core->ctl, &c, &core->weights);
  });
}
extern "C" void poursim_core_destroy(poursim_core_t *core) { delete core; }
extern "C" int poursim_core_update(poursim_core_t *core, const pour_control_input_t *in) {
  return pour_control_update(&core->ctl, in) ? 1 : 0;
}
extern "C" void poursim_core_state(const poursim_core_t *core, pour_state_t *state) {
  *state = *pour_control_state(&core->ctl);
}
extern "C" void poursim_core_decide(poursim_core_t *core) { pour_control_decide(&core->ctl); }
extern "C" void poursim_core_request(poursim_core_t *core, uint8_t action, int16_t torque) {
  pour_control_request(&core->ctl, action, torque);
}
extern "C" void poursim_core_shape(poursim_core_t *core, pour_control_output_t *out) {
  pour_control_shape(&core->ctl, out);
}
extern "C" void poursim_core_step(poursim_core_t *core, const pour_control_input_t *in, pour_control_output_t *out) {
  pour_control_step(&core->ctl, in, out);
  pour_control_probs(&core->ctl, out); /* Python's Output.probs: the latest decision's, as the Linux port reports */
}
