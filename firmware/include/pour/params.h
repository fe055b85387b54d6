/* SPDX-License-Identifier: MIT */
/* The controller's tunable parameters: one table (POUR_PARAMS) gives each its id, name, unit, default, range
 * and the field it lives in. The modules' default configs take their defaults from it, the node's get/set and
 * range checks, the bus's value lists (can/pour.dbc), the docs' tables and Python's field table are generated
 * from it or read it (scripts/param_table.py checks that each agrees). Values are int32 in the field's unit.
 * Get/set by id with range checks, the sample correction (encoder zero, scale tare and factor), a storage blob
 * with a version and a CRC-32, and putting a new set in force in the core. Pure: no I/O.
 * The motor's parameters and the current-loop bandwidth join the table with the motor library. */
#ifndef POUR_PARAMS_H
#define POUR_PARAMS_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/control.h"
#include "pour/fixed.h"
#include "pour/safety.h"
#include "pour/sensors.h"

#define POUR_PARAM_FACTOR_ONE 1000000 /* a scale factor of 1.0 [ppm] */

/* The safety case's ranges (docs/safety.md, "Ranges the node accepts"), not the types': a
 * write beyond them is refused (POUR_PARAM_OUT_OF_RANGE) on the node, over CAN and from flash. They are compiled
 * in; widening one is a reviewed change of this file and a new firmware build, never a bus write. */
#define POUR_PARAM_OMEGA_ENVELOPE_URAD_S 2000000   /* 2 rad/s: the hot-liquid limit, omega_max's default */
#define POUR_PARAM_ALPHA_ENVELOPE_URAD_S2 3400000  /* 3.4 rad/s^2: omega_max in one 1.7 Hz slosh period */
#define POUR_PARAM_GAIN_ENVELOPE 16384             /* 0.5 tau_max per rad/s: the stiffest stable governor */
#define POUR_PARAM_THETA_LOW_URAD (-87266)         /* -5 deg: a little past upright, never backwards over */
#define POUR_PARAM_THETA_HIGH_URAD 2356194         /* 135 deg: the hard stop of the bucket's tilt */
/* The supervisor's and the estimator's limits a commissioning engineer may tighten but not loosen: beyond them
 * a fault is detected later or not at all (docs/safety.md, "Ranges the node accepts"; docs/hazards.md). */
#define POUR_PARAM_THETA_MARGIN_URAD 87266         /* 5 deg: POSITION at most this far past the envelope's limits */
#define POUR_PARAM_OVERSPEED_URAD_S 4000000        /* 4 rad/s: OVERSPEED at most twice the hot-liquid limit */
#define POUR_PARAM_JUMP_URAD 10000                 /* 10 mrad: a count at most this far off its prediction */

/* X(id, name, unit, default, min, max, C type, group, member, doc). The row's field is
 * POUR_PARAM_IN_<group>(member) of pour_params_t: the group names the config struct it lives in, and that
 * struct's default config (pour_safety_default_config, pour_sensors_default_config,
 * pour_supervisor_default_config, pour_control_default_config's stop, and pour_params_default for the port's
 * own) sets each member to the row's default, so a default is written once, here. doc says in one line why it
 * is the default (docs/safety.md shows it, beside the longer arguments of "Defaults and why"). Ids are the
 * bus's: ParamId's value lists in can/pour.dbc are what scripts/param_table.py dbc --write writes from this
 * table. A default outside [min, max], two rows on one id or two of one name fail the build: scripts/
 * param_table.py check names the rows, and the compiler (params.c) refuses them too. */
#define POUR_PARAMS(X)                                                                                               \
  /* the motion envelope (pour_safety_config_t; docs/safety.md, "Defaults and why") */                               \
  X(0, tau_limit, "Q15", POUR_Q15_MAX, 1, POUR_Q15_MAX, q15_t, safety, tau_limit,                                    \
    "1.0 tau_max: the policy was trained against tau_max; lower it on a bench to be gentle")                         \
  X(1, slew_per_tick, "Q15", 3277, 1, POUR_Q15_MAX, q15_t, safety, slew_per_tick,                                    \
    "a full -1 to +1 swing in 20 ms (two decision periods): no torque steps into the gearbox or the liquid")         \
  X(2, theta_min, "urad", POUR_PARAM_THETA_LOW_URAD, POUR_PARAM_THETA_LOW_URAD, POUR_PARAM_THETA_HIGH_URAD,          \
    int32_t, safety, theta_min_urad,                                                                                 \
    "-5 deg: a little past upright so the bucket can settle, never backwards over")                                  \
  X(3, theta_max, "urad", POUR_PARAM_THETA_HIGH_URAD, POUR_PARAM_THETA_LOW_URAD, POUR_PARAM_THETA_HIGH_URAD,         \
    int32_t, safety, theta_max_urad,                                                                                 \
    "135 deg: the bucket's hard stop (the simulator's joint limit): never push into it")                             \
  X(4, omega_max, "urad/s", POUR_PARAM_OMEGA_ENVELOPE_URAD_S, 1, POUR_PARAM_OMEGA_ENVELOPE_URAD_S, int32_t, safety,  \
    omega_max_urad_s,                                                                                                \
    "2 rad/s: 93 degC liquid stays in the bucket (the hot-liquid limit)")                                            \
  X(5, alpha_max, "urad/s2", POUR_PARAM_ALPHA_ENVELOPE_URAD_S2, 1000, POUR_PARAM_ALPHA_ENVELOPE_URAD_S2, int32_t,    \
    safety, alpha_max_urad_s2,                                                                                       \
    "3.4 rad/s^2: omega_max reached in one period of the 1.7 Hz slosh mode, which the ramp then leaves at rest")     \
  X(6, omega_slack, "urad/s", 800000, 1, POUR_PARAM_OMEGA_ENVELOPE_URAD_S, int32_t, safety, omega_slack_urad_s,      \
    "0.8 rad/s: K * slack = 0.4 tau_max holds and starts the full bucket, above the supervisor's torque_min")        \
  X(7, governor_gain, "Q15/(rad/s)", POUR_PARAM_GAIN_ENVELOPE, 1, POUR_PARAM_GAIN_ENVELOPE, q15_t, safety,           \
    governor_gain,                                                                                                   \
    "0.5 tau_max per rad/s: the stiffest governor stable on the lightest load with 2 ticks of latency")              \
  /* the controlled stop (pour_stop_config_t; docs/safety.md, "Defaults", controlled stop) */                        \
  X(8, stop_torque_max, "Q15", 16384, 1, POUR_Q15_MAX, q15_t, stop, torque_max,                                      \
    "0.5 tau_max: decelerates 16 rad/s in well under 0.2 s, gently enough not to throw the liquid")                  \
  X(9, stop_return_speed, "urad/s", 1000000, 1, POUR_PARAM_OMEGA_ENVELOPE_URAD_S, int32_t, stop, return_speed_urad_s,\
    "1 rad/s: back toward upright slowly, no slosh over the lip")                                                    \
  X(10, stop_return_gain, "1/s", 2, 1, UINT16_MAX, uint16_t, stop, return_gain_per_s,                                \
    "the speed reference falls to 0 over the last half radian")                                                      \
  X(11, stop_gain, "Q15/(rad/s)", 16384, 1, POUR_PARAM_GAIN_ENVELOPE, q15_t, stop, gain,                             \
    "0.5 tau_max per rad/s of speed error")                                                                          \
  X(12, stop_rest_theta, "urad", 87266, 1, 3141593, int32_t, stop, rest_theta_urad,                                  \
    "5 deg of upright: at rest, as the fault tests measure it")                                                      \
  X(13, stop_rest_omega, "urad/s", 50000, 1, POUR_PARAM_OMEGA_ENVELOPE_URAD_S, int32_t, stop, rest_omega_urad_s,     \
    "0.05 rad/s: at rest, as the fault tests measure it")                                                            \
  X(14, stop_timeout, "ms", 5000, 1, UINT16_MAX, uint16_t, stop, timeout_ms,                                         \
    "from 135 deg at 1 rad/s takes 2.4 s: twice that, then brake anyway")                                            \
  /* the node, the encoder, the gearbox and the load cells (the port's own, and pour_sensors_config_t) */            \
  X(15, node_id, "", 0, 0, 63, uint8_t, port, node_id,                                                               \
    "the port binds it at start-up (its command line, the board's stored set)")                                      \
  X(16, encoder_bits, "bits", 17, POUR_ENCODER_BITS_MIN, POUR_ENCODER_BITS_MAX, uint8_t, sensors, encoder_bits,      \
    "the bench rig's absolute encoder (47.9 urad a count)")                                                          \
  X(17, encoder_zero, "counts", 0, 0, 16777215, int32_t, port, encoder_zero,                                         \
    "uncalibrated: the raw count read upright, set by the calibration")                                              \
  X(18, gear_ratio, "1/1000", 1000, 1000, 1000000, int32_t, port, gear_ratio_milli,                                  \
    "motor turns per output turn (the drive's: motor torque = output torque / ratio); 1 until the rig's is set")     \
  X(19, scale_rotating_factor, "ppm", POUR_PARAM_FACTOR_ONE, 500000, 2000000, int32_t, port,                         \
    scale_rotating_factor_ppm,                                                                                       \
    "uncalibrated: grams = (reading - tare) * factor, factor 1.0")                                                   \
  X(20, scale_rotating_tare, "g", 0, -32767, 32767, int32_t, port, scale_rotating_tare_g,                            \
    "uncalibrated: no tare (the reading with the rotating bucket empty)")                                            \
  X(21, scale_target_factor, "ppm", POUR_PARAM_FACTOR_ONE, 500000, 2000000, int32_t, port, scale_target_factor_ppm,  \
    "uncalibrated: factor 1.0")                                                                                      \
  X(22, scale_target_tare, "g", 0, -32767, 32767, int32_t, port, scale_target_tare_g,                                \
    "uncalibrated: no tare")                                                                                         \
  /* the motion envelope's fill schedule (pour_safety_config_t; docs/safety.md, "Fill schedule") */                  \
  X(23, knee_theta, "urad", 0, 0, POUR_SAFETY_KNEE_MAX_URAD, int32_t, safety, knee_theta_urad,                       \
    "0: off; the rig file gives the knee, its fill's onset angle less 3 deg")                                        \
  X(24, slow_omega, "urad/s", 160000, 1, POUR_PARAM_OMEGA_ENVELOPE_URAD_S, int32_t, safety, slow_omega_urad_s,       \
    "0.16 rad/s past the knee: 11-12 L leave no faster than the target takes them")                                  \
  X(25, knee_decel, "urad/s2", 10000000, 1000, POUR_SAFETY_DECEL_MAX_URAD_S2, int32_t, safety, knee_decel_urad_s2,   \
    "10 rad/s^2: 2 rad/s down to 0.16 rad/s within 0.2 rad (11 deg) before the knee")                                \
  X(26, slow_torque_ff, "Q15", 1638, 0, POUR_Q15_MAX, q15_t, safety, slow_torque_ff,                                 \
    "0.05 tau_max = 1 N m: the part of the load the integral need not build up")                                     \
  X(27, slow_ki, "1/s", 5, 0, UINT16_MAX, uint16_t, safety, slow_ki_per_s,                                           \
    "K * 5/s * 0.16 rad/s = 8 N m/s: the integral takes up a full bucket's 3-5 N m within a second")                 \
  /* the supervisor's limits and the estimator's jump limit (docs/safety.md, "Ranges the node accepts") */           \
  X(28, supervisor_theta_margin, "urad", POUR_PARAM_THETA_MARGIN_URAD, 1, POUR_PARAM_THETA_MARGIN_URAD, int32_t,     \
    supervisor, theta_margin_urad,                                                                                   \
    "5 deg past the envelope's limits: an overshoot no nominal pour shows (nominal -0.0 .. 128.4 deg)")              \
  X(29, supervisor_omega_max, "urad/s", POUR_PARAM_OVERSPEED_URAD_S, 1, POUR_PARAM_OVERSPEED_URAD_S, int32_t,        \
    supervisor, omega_max_urad_s,                                                                                    \
    "4 rad/s, twice the envelope's limit: a speed the governor could not hold (its droop is <= 0.54 rad/s)")         \
  X(30, jump_max, "urad", POUR_PARAM_JUMP_URAD, 1, POUR_PARAM_JUMP_URAD, int32_t, sensors, jump_max_urad,            \
    "10 mrad: the loop lags that far only beyond 900 rad/s^2; a count further off its prediction jumped")

/* One name per parameter. A row's name is the one the bus (ParamId), pour-bench, the docs and the node's table
 * use; its member is that name without its group's prefix (stop_ for the controlled stop's rows, supervisor_
 * for the supervisor's, none for the others) and with its unit's suffix: _urad, _urad_s, _urad_s2, _ms,
 * _per_s (1/s), _ppm, _g, _milli (1/1000); none for Q15, Q15/(rad/s), bits, counts and plain numbers. So
 * theta_max is safety.theta_max_urad, stop_timeout stop.timeout_ms, governor_gain safety.governor_gain; Python
 * and the simulator's bridge reach a field by its C path (control.safety.theta_max_urad). scripts/param_table.py
 * check holds every row to this rule. A rig file's fill_schedule_l is no parameter: it is the fill [L] from
 * which the simulator sets a rig's knee_theta. */

/* Where each group's members live in pour_params_t. */
#define POUR_PARAM_IN_safety(member) control.safety.member
#define POUR_PARAM_IN_stop(member) control.stop.member
#define POUR_PARAM_IN_sensors(member) control.sensors.member
#define POUR_PARAM_IN_supervisor(member) control.supervisor.member
#define POUR_PARAM_IN_port(member) member

/* The number of rows (ids 0 .. count - 1). */
#define POUR_PARAM_PLUS_ONE(...) +1u
#define POUR_PARAM_COUNT (0u POUR_PARAMS(POUR_PARAM_PLUS_ONE))

/* POUR_PARAM_ID_<name>: each parameter's id, from the table. */
typedef enum {
#define POUR_PARAM_ENUM(id, name, unit, def, lo, hi, type, group, member, doc) POUR_PARAM_ID_##name = id,
  POUR_PARAMS(POUR_PARAM_ENUM)
#undef POUR_PARAM_ENUM
} pour_param_id_t;

/* Where the parameters live: the core's configuration and the port's own. */
typedef struct {
  pour_control_config_t control;
  uint8_t node_id;                   /* CAN node id; the port binds it at start-up */
  int32_t encoder_zero;              /* raw count read upright [counts], < 2^encoder_bits */
  int32_t gear_ratio_milli;          /* motor turns per output turn [1/1000] */
  int32_t scale_rotating_factor_ppm; /* grams per reading unit [ppm] */
  int32_t scale_rotating_tare_g;     /* reading with the rotating bucket empty [g] */
  int32_t scale_target_factor_ppm;
  int32_t scale_target_tare_g;
} pour_params_t;

typedef struct {
  uint8_t id;
  const char *name;
  const char *unit;
  int32_t min; /* valid values: min .. max, inclusive */
  int32_t max;
  int32_t default_value; /* the compiled default (the port's own node id aside) */
} pour_param_info_t;

/* How a parameter request or a stored set is judged. */
typedef enum {
  POUR_PARAM_OK = 0,
  POUR_PARAM_UNKNOWN_ID = 1,   /* no parameter has this id */
  POUR_PARAM_OUT_OF_RANGE = 2, /* the value lies outside the parameter's [min, max] */
  POUR_PARAM_BUSY = 3,         /* the core runs (RUN, ESTOP, or a controlled stop under way) */
  POUR_PARAM_INCONSISTENT = 4, /* in range, but the set as a whole is refused (e.g. theta_min >= theta_max) */
  POUR_PARAM_NO_STORAGE = 5,   /* save: the controller has no storage, or writing it failed */
  POUR_PARAM_NO_SAMPLE = 6     /* tare, zero: no sensor sample has arrived yet */
} pour_param_result_t;

/* The name of a result ("ok", "unknown id", ...). */
const char *pour_param_result_name(pour_param_result_t result);

/* Table row of id, or NULL. */
const pour_param_info_t *pour_param_info(uint8_t id);

/* The defaults: control as given (the port's command line on top of pour_control_default_config), node_id,
 * and the port's own rows (group port) at their declared defaults: no encoder zero offset, gear ratio 1,
 * factors 1.0, tares 0. */
void pour_params_default(pour_params_t *params, const pour_control_config_t *control, uint8_t node_id);

/* The value of id; POUR_PARAM_UNKNOWN_ID otherwise (*value untouched). */
pour_param_result_t pour_params_get(const pour_params_t *params, uint8_t id, int32_t *value);

/* Sets id to value after the range check (the set's consistency is pour_params_check's). */
pour_param_result_t pour_params_set(pour_params_t *params, uint8_t id, int32_t value);

/* The rules between parameters that the table's ranges cannot say and the core does not check
 * (encoder_zero < 2^encoder_bits). The core's own rules are checked when the set is put in force. */
pour_param_result_t pour_params_check(const pour_params_t *params);

/* A raw sample as the core must see it: encoder (count - zero) mod 2^bits (a count >= 2^bits passes as it
 * is, so that the core still refuses it), scales (reading - tare) * factor, rounded half away from zero. */
void pour_params_correct(const pour_params_t *params, pour_sensors_t *sample);

/* True if the core takes a new configuration now: IDLE, or FAULT once the controlled stop is over. */
bool pour_params_writable(const pour_control_t *ctl);

/* Puts params->control in force in ctl (pour_control_init; with weights NULL, pour_control_init_external with
 * ctl's decision period), which must be writable: IDLE stays IDLE; FAULT
 * keeps its latched faults, the brake and the tick count. POUR_EINVAL (ctl unchanged in effect: the old
 * configuration is put back) if the core refuses the configuration or ctl is not writable. */
pour_status_t pour_params_apply(pour_control_t *ctl, const pour_params_t *params,
                                const pour_policy_weights_t *weights);

/* Storage blob, little-endian: magic "PPRM", version u16, count u16, count x (id u8, value i32), CRC-32 (IEEE
 * 802.3) of all bytes before it. */
#define POUR_PARAMS_BLOB_VERSION 1u
#define POUR_PARAMS_BLOB_MAX (8u + 5u * POUR_PARAM_COUNT + 4u)

typedef enum {
  POUR_PARAMS_BLOB_OK = 0,
  POUR_PARAMS_BLOB_TRUNCATED = -1,   /* shorter than its header says, or than a header */
  POUR_PARAMS_BLOB_BAD_MAGIC = -2,   /* not a parameter blob */
  POUR_PARAMS_BLOB_BAD_VERSION = -3, /* another layout version */
  POUR_PARAMS_BLOB_BAD_CRC = -4,     /* corrupt */
  POUR_PARAMS_BLOB_BAD_VALUE = -5    /* an unknown id, a value out of its range, or an inconsistent set */
} pour_params_blob_t;

const char *pour_params_blob_name(pour_params_blob_t status);

/* Writes the whole set into buf (cap >= POUR_PARAMS_BLOB_MAX); returns the length, 0 if it does not fit. */
uint32_t pour_params_serialize(const pour_params_t *params, uint8_t *buf, uint32_t cap);

/* Reads a blob onto *params (ids it lacks keep their values). On POUR_PARAMS_BLOB_BAD_VALUE *bad_id names the
 * parameter; *params is written only on POUR_PARAMS_BLOB_OK. */
pour_params_blob_t pour_params_deserialize(const uint8_t *buf, uint32_t len, pour_params_t *params,
                                           uint8_t *bad_id);

/* CRC-32 (IEEE 802.3, reflected, init and final xor 0xFFFFFFFF) of len bytes. */
uint32_t pour_crc32(const uint8_t *data, uint32_t len);

#endif /* POUR_PARAMS_H */
