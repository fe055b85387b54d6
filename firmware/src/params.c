/* SPDX-License-Identifier: MIT */
#include "pour/params.h"

#include <stddef.h>

#define BLOB_MAGIC 0x4D525050u /* "PPRM" little-endian */
#define BLOB_HEADER 8u
#define BLOB_RECORD 5u
#define BLOB_CRC 4u

static const pour_param_info_t k_info[] = {
#define POUR_PARAM_INFO(id, name, unit, def, lo, hi, type, group, member, doc) {id, #name, unit, lo, hi, def},
    POUR_PARAMS(POUR_PARAM_INFO)
#undef POUR_PARAM_INFO
};

/* The declaration checked by the compiler as well (scripts/param_table.py check names the rows in the build):
 * two rows on one id are two equal case labels in pour_params_get, two of one name two equal enumerators, an
 * empty range or a default outside its row's range a negative array size here, named for the row. (Arrays, not
 * _Static_assert: under -std=c99 glibc's stand-in for _Static_assert drops the message and with it the row.) */
#define POUR_PARAM_RANGE_CHECK(id, name, unit, def, lo, hi, type, group, member, doc)   \
  typedef char pour_param_range_not_empty_##name[(lo) <= (hi) ? 1 : -1];           \
  typedef char pour_param_default_in_range_##name[(lo) <= (def) && (def) <= (hi) ? 1 : -1];
POUR_PARAMS(POUR_PARAM_RANGE_CHECK)
#undef POUR_PARAM_RANGE_CHECK

/* The table is dense: row i has id i (a Unity test checks it), so the lookup is an index. */
const pour_param_info_t *pour_param_info(uint8_t id) {
  return id < POUR_PARAM_COUNT ? &k_info[id] : NULL;
}

const char *pour_param_result_name(pour_param_result_t result) {
  switch (result) {
    case POUR_PARAM_OK: return "ok";
    case POUR_PARAM_UNKNOWN_ID: return "unknown id";
    case POUR_PARAM_OUT_OF_RANGE: return "out of range";
    case POUR_PARAM_BUSY: return "busy (not in IDLE or FAULT)";
    case POUR_PARAM_INCONSISTENT: return "inconsistent with the other parameters";
    case POUR_PARAM_NO_STORAGE: return "no storage";
    case POUR_PARAM_NO_SAMPLE: return "no sensor sample yet";
    default: return "unknown result";
  }
}

/* The port's own rows at their declared defaults; the other groups' come with control. */
#define PARAMS_ROW_safety(member, type, value)
#define PARAMS_ROW_stop(member, type, value)
#define PARAMS_ROW_sensors(member, type, value)
#define PARAMS_ROW_supervisor(member, type, value)
#define PARAMS_ROW_port(member, type, value) params->member = (type)(value);
#define PARAMS_DEFAULT(id, name, unit, def, lo, hi, type, group, member, doc) PARAMS_ROW_##group(member, type, def)

void pour_params_default(pour_params_t *params, const pour_control_config_t *control, uint8_t node_id) {
  params->control = *control;
  POUR_PARAMS(PARAMS_DEFAULT)
  params->node_id = node_id;
}

pour_param_result_t pour_params_get(const pour_params_t *params, uint8_t id, int32_t *value) {
  switch (id) {
#define POUR_PARAM_GET(pid, name, unit, def, lo, hi, type, group, member, doc) \
  case pid: *value = (int32_t)params->POUR_PARAM_IN_##group(member); return POUR_PARAM_OK;
    POUR_PARAMS(POUR_PARAM_GET)
#undef POUR_PARAM_GET
    default: return POUR_PARAM_UNKNOWN_ID;
  }
}

pour_param_result_t pour_params_set(pour_params_t *params, uint8_t id, int32_t value) {
  const pour_param_info_t *info = pour_param_info(id);
  if (info == NULL) {
    return POUR_PARAM_UNKNOWN_ID;
  }
  if (value < info->min || value > info->max) {
    return POUR_PARAM_OUT_OF_RANGE;
  }
  switch (id) {
#define POUR_PARAM_SET(pid, name, unit, def, lo, hi, type, group, member, doc) \
  case pid: params->POUR_PARAM_IN_##group(member) = (type)value; break;
    POUR_PARAMS(POUR_PARAM_SET)
#undef POUR_PARAM_SET
    default: break;
  }
  return POUR_PARAM_OK;
}

pour_param_result_t pour_params_check(const pour_params_t *params) {
  const uint8_t bits = params->control.sensors.encoder_bits;
  if (bits < POUR_ENCODER_BITS_MIN || bits > POUR_ENCODER_BITS_MAX ||
      (uint32_t)params->encoder_zero >= (1u << bits)) {
    return POUR_PARAM_INCONSISTENT;
  }
  return POUR_PARAM_OK;
}

/* (reading - tare) * factor / 10^6, rounded half away from zero; |result| < 2^31 since |reading - tare| < 2^17
 * and factor <= 2 * 10^6. */
static int32_t scale_grams(int32_t reading, int32_t tare, int32_t factor_ppm) {
  const int64_t p = ((int64_t)reading - tare) * factor_ppm;
  const int64_t half = POUR_PARAM_FACTOR_ONE / 2;
  return (int32_t)(p >= 0 ? (p + half) / POUR_PARAM_FACTOR_ONE : -((-p + half) / POUR_PARAM_FACTOR_ONE));
}

void pour_params_correct(const pour_params_t *params, pour_sensors_t *sample) {
  const uint32_t counts = 1u << params->control.sensors.encoder_bits;
  if (sample->encoder < counts) {
    sample->encoder = (sample->encoder - (uint32_t)params->encoder_zero) & (counts - 1u);
  }
  sample->scale_rotating_g =
      scale_grams(sample->scale_rotating_g, params->scale_rotating_tare_g, params->scale_rotating_factor_ppm);
  sample->scale_target_g =
      scale_grams(sample->scale_target_g, params->scale_target_tare_g, params->scale_target_factor_ppm);
}

bool pour_params_writable(const pour_control_t *ctl) {
  return ctl->mode == POUR_MODE_IDLE || (ctl->mode == POUR_MODE_FAULT && ctl->stopped);
}

static pour_status_t reinit(pour_control_t *ctl, const pour_control_config_t *config,
                            const pour_policy_weights_t *weights, uint16_t period) {
  return weights != NULL ? pour_control_init(ctl, config, weights) : pour_control_init_external(ctl, config, period);
}

pour_status_t pour_params_apply(pour_control_t *ctl, const pour_params_t *params,
                                const pour_policy_weights_t *weights) {
  if (ctl == NULL || params == NULL || !pour_params_writable(ctl)) {
    return POUR_EINVAL;
  }
  /* What holds the axis survives the new configuration: a latched fault (only clear_faults ends it), the
   * hold after an experiment (only a Reset or another experiment ends it) with the empty bucket it expects,
   * the last trusted angle that a restart of the held axis must find again, the drive's trust, the command
   * on the wire (no step) and the count of refusals the bus reports. */
  const pour_control_config_t old = ctl->config;
  const pour_mode_t mode = ctl->mode;
  const uint16_t faults = ctl->faults;
  const uint32_t tick = ctl->tick;
  const uint32_t refused = ctl->refused;
  const bool held = ctl->held;
  const bool empty_ok = ctl->estimator.empty_ok;
  const bool have_trusted = ctl->have_trusted;
  const int32_t trusted_theta_urad = ctl->trusted_theta_urad;
  const bool check_restart = ctl->check_restart;
  const bool drive_untrusted = ctl->drive_untrusted;
  const q15_t on_wire = ctl->safety.torque;
  /* A controller whose decisions come from outside (no weights) stays one, with its decision period. */
  const uint16_t period = ctl->decision_period_ms;
  pour_status_t s = reinit(ctl, &params->control, weights, period);
  if (s != POUR_OK) {
    (void)reinit(ctl, &old, weights, period); /* accepted before, so accepted again */
    s = POUR_EINVAL;
  }
  ctl->mode = mode;
  ctl->faults = faults;
  ctl->stopped = mode == POUR_MODE_FAULT;
  ctl->tick = tick;
  ctl->refused = refused;
  ctl->held = held;
  pour_estimator_expect_empty(&ctl->estimator, empty_ok);
  ctl->have_trusted = have_trusted;
  ctl->trusted_theta_urad = trusted_theta_urad;
  ctl->check_restart = check_restart;
  ctl->drive_untrusted = drive_untrusted;
  const q15_t lim = ctl->config.safety.tau_limit; /* the command on the wire, within the new clamp */
  pour_safety_force(&ctl->safety, on_wire > lim ? lim : (on_wire < -lim ? (q15_t)-lim : on_wire));
  return s;
}

const char *pour_params_blob_name(pour_params_blob_t status) {
  switch (status) {
    case POUR_PARAMS_BLOB_OK: return "ok";
    case POUR_PARAMS_BLOB_TRUNCATED: return "truncated";
    case POUR_PARAMS_BLOB_BAD_MAGIC: return "not a parameter file (bad magic)";
    case POUR_PARAMS_BLOB_BAD_VERSION: return "unsupported layout version";
    case POUR_PARAMS_BLOB_BAD_CRC: return "CRC mismatch (corrupt)";
    case POUR_PARAMS_BLOB_BAD_VALUE: return "a parameter is unknown, out of range or inconsistent";
    default: return "unknown status";
  }
}

uint32_t pour_crc32(const uint8_t *data, uint32_t len) {
  uint32_t crc = 0xFFFFFFFFu;
  for (uint32_t i = 0; i < len; ++i) {
    crc ^= data[i];
    for (int b = 0; b < 8; ++b) {
      crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
  }
  return ~crc;
}

static void put_u32(uint8_t *p, uint32_t v) {
  for (int i = 0; i < 4; ++i) {
    p[i] = (uint8_t)((v >> (8 * i)) & 0xFFu);
  }
}

static uint32_t get_u32(const uint8_t *p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

uint32_t pour_params_serialize(const pour_params_t *params, uint8_t *buf, uint32_t cap) {
  if (params == NULL || buf == NULL || cap < POUR_PARAMS_BLOB_MAX) {
    return 0u;
  }
  put_u32(buf, BLOB_MAGIC);
  buf[4] = (uint8_t)(POUR_PARAMS_BLOB_VERSION & 0xFFu);
  buf[5] = (uint8_t)(POUR_PARAMS_BLOB_VERSION >> 8);
  buf[6] = (uint8_t)POUR_PARAM_COUNT;
  buf[7] = 0u;
  uint32_t n = BLOB_HEADER;
  for (uint8_t id = 0; id < POUR_PARAM_COUNT; ++id) {
    int32_t v = 0;
    (void)pour_params_get(params, id, &v);
    buf[n] = id;
    put_u32(&buf[n + 1u], (uint32_t)v);
    n += BLOB_RECORD;
  }
  put_u32(&buf[n], pour_crc32(buf, n));
  return n + BLOB_CRC;
}

/* Two's complement reinterpretation without implementation-defined conversion. */
static int32_t as_i32(uint32_t v) { return (v & 0x80000000u) ? -(int32_t)(~v) - 1 : (int32_t)v; }

pour_params_blob_t pour_params_deserialize(const uint8_t *buf, uint32_t len, pour_params_t *params,
                                           uint8_t *bad_id) {
  if (buf == NULL || params == NULL || len < BLOB_HEADER + BLOB_CRC) {
    return POUR_PARAMS_BLOB_TRUNCATED;
  }
  if (get_u32(buf) != BLOB_MAGIC) {
    return POUR_PARAMS_BLOB_BAD_MAGIC;
  }
  if ((uint32_t)(buf[4] | (buf[5] << 8)) != POUR_PARAMS_BLOB_VERSION) {
    return POUR_PARAMS_BLOB_BAD_VERSION;
  }
  const uint32_t count = (uint32_t)(buf[6] | (buf[7] << 8));
  const uint32_t body = BLOB_HEADER + count * BLOB_RECORD;
  if (len < body + BLOB_CRC) {
    return POUR_PARAMS_BLOB_TRUNCATED;
  }
  if (len != body + BLOB_CRC || pour_crc32(buf, body) != get_u32(&buf[body])) {
    return POUR_PARAMS_BLOB_BAD_CRC;
  }
  pour_params_t p = *params;
  for (uint32_t i = 0; i < count; ++i) {
    const uint8_t *r = &buf[BLOB_HEADER + i * BLOB_RECORD];
    if (pour_params_set(&p, r[0], as_i32(get_u32(&r[1]))) != POUR_PARAM_OK) {
      if (bad_id != NULL) {
        *bad_id = r[0];
      }
      return POUR_PARAMS_BLOB_BAD_VALUE;
    }
  }
  if (pour_params_check(&p) != POUR_PARAM_OK) {
    if (bad_id != NULL) {
      *bad_id = (uint8_t)POUR_PARAM_ID_encoder_zero; /* the one rule between parameters */
    }
    return POUR_PARAMS_BLOB_BAD_VALUE;
  }
  *params = p;
  return POUR_PARAMS_BLOB_OK;
}
