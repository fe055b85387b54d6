/* SPDX-License-Identifier: MIT */
/* libpoursim: the pouring world (Box2D 3), its configuration, and a whole-episode rollout for training.
 * Plain C API (usable from C, C++ and Python ctypes). Units: SI (m, kg, s, rad, N·m) unless stated.
 * Angles: θ = 0 upright, positive tilts the rotating bucket toward the target (clockwise on screen,
 * target on the right). */
#ifndef POURSIM_POURSIM_H
#define POURSIM_POURSIM_H

#include <stddef.h>
#include <stdint.h>

#include "poursim/config_fields.h"

#ifdef __cplusplus
extern "C" {
#endif

#define POURSIM_N_FEATURES 6    /* θn, ωn, V_rotating, V_target, V_spill, bias 1.0 */
#define POURSIM_MAX_ACTIONS 16
#define POURSIM_MAX_PARTICLES 1024
#define POURSIM_ERR_LEN 256     /* size of the error buffers the API fills */

/* Status of every fallible call: 0 = OK, negative = error (the error text says what). */
typedef enum {
  POURSIM_OK = 0,
  POURSIM_EINVAL = -1, /* an argument or config value out of range */
  POURSIM_EIO = -2,    /* a file could not be read */
  POURSIM_EPARSE = -3, /* a file could not be parsed */
  POURSIM_ESTATE = -4, /* call out of order (e.g. step after the episode ended) */
  POURSIM_ENUMERIC = -5 /* the simulation blew up numerically (poursim_world_error says where) */
} poursim_status_t;

/* The whole configuration: one field per key of config_fields.h, which holds each one's type, default,
 * range, unit and meaning. */
typedef struct {
#define POURSIM_CONFIG_MEMBER(kind, name, def, lo, hi, unit, doc) POURSIM_CONFIG_CTYPE_##kind name;
#define POURSIM_CONFIG_NO_SECTION(title)
  POURSIM_CONFIG_FIELDS(POURSIM_CONFIG_MEMBER, POURSIM_CONFIG_NO_SECTION)
#undef POURSIM_CONFIG_MEMBER
#undef POURSIM_CONFIG_NO_SECTION
} poursim_config_t;

/* Everything measured after a step (or at reset). */
typedef struct {
  uint32_t step;        /* steps since t = 0 */
  double t;             /* [s] */
  double theta;         /* [rad] */
  double omega;         /* [rad/s] */
  double v_rotating;    /* fraction of circles inside the rotating bucket (its frame) */
  double v_target;      /* fraction inside the target bucket */
  double v_spill;       /* fraction outside both and below the target's rim, or on the ground */
  double v_flight;      /* fraction in none of those (in the air) */
  double torque;        /* torque commanded in the step that led here, a·tau_max [N·m] */
  int done;             /* 1 once t reaches episode_s */
  /* What the rig delivers and senses (docs/simulator.md, "The rig"). */
  double motor_torque;  /* torque the drive delivered at the output in that step (after latency, peak and
                           back-EMF limits; friction acts on top) [N·m] */
  uint32_t encoder;     /* output-shaft absolute encoder: round(θ·2^bits/2π) mod 2^bits (0 = upright) */
  int32_t scale_rotating_g; /* load cell carrying the rotating bucket, tared empty [g] */
  int32_t scale_target_g;   /* load cell under the target bucket, tared empty [g] */
  uint32_t drive_faults;    /* the full drive's (drive = 1) latched faults, POUR_DRIVE_FAULT_*; 0 otherwise */
  int drive_trusted;        /* 1 while the drive still follows a torque (no full drive, or its loop runs), else 0 */
} poursim_obs_t;

typedef struct poursim_world poursim_world_t;

/* What the full drive (config drive = 1) saw since the last reset; zeros with the ideal drive. */
typedef struct {
  double peak_current;  /* largest |phase current| [A] */
  double peak_vbus;     /* highest bus voltage [V] */
  double min_vbus;      /* lowest bus voltage [V] */
  uint32_t faults;      /* the drive's latched faults (firmware/motor/include/pour/drive_faults.h) */
  uint32_t limits;      /* every POUR_DRIVE_LIMIT_* flag raised (pour/drive.h) */
} poursim_drive_telemetry_t;

/* Defaults of the paper's scene (docs/simulator.md). */
poursim_config_t poursim_default_config(void);

/* Checks every field; on error writes a message naming the field into err (may be NULL). */
int poursim_config_validate(const poursim_config_t *config, char *err, size_t err_len);

/* Reads "key = value" lines (# comments) over the values already in *config, then validates. */
int poursim_config_load(const char *path, poursim_config_t *config, char *err, size_t err_len);

/* Sets one field by name from text (the same keys as the config file). */
int poursim_config_set(poursim_config_t *config, const char *key, const char *value, char *err,
                       size_t err_len);

/* Every config key with its unit, range and default, one a line (for --help); POURSIM_EINVAL if buf is
 * too small (8 KiB is plenty). */
int poursim_config_describe(char *buf, size_t len);

/* Writes the config as a loadable file: a banner, then every key with its unit and meaning, in the order
 * of config_fields.h. Written from poursim_default_config() it is configs/sim/default.cfg. */
int poursim_config_write(const poursim_config_t *config, const char *path, char *err, size_t err_len);

/* A config on the heap, for callers that hold it as an opaque handle (Python): the defaults, or a copy of
 * src when src is not NULL. NULL if out of memory. Free with poursim_config_free. */
poursim_config_t *poursim_config_new(const poursim_config_t *src);
void poursim_config_free(poursim_config_t *config);

/* Reads one field by name into *value (integers exactly); POURSIM_EINVAL naming the key if unknown. */
int poursim_config_get(const poursim_config_t *config, const char *key, double *value, char *err, size_t err_len);

/* The name of key number index (0, 1, ... in config_fields.h order); NULL past the last. */
const char *poursim_config_key(int index);

/* A key's declaration: integer (1) or real (0), inclusive range, default, unit and one line on its meaning.
 * Any output pointer may be NULL; POURSIM_EINVAL if the key is unknown. */
int poursim_config_key_info(const char *key, int *integer, double *min, double *max, double *def,
                            const char **unit, const char **doc);

/* Creates a world (validates the config) and resets it with config->seed. NULL on error. */
poursim_world_t *poursim_create(const poursim_config_t *config, char *err, size_t err_len);

/* Rebuilds the scene: new liquid arrangement from seed, settled, bucket upright at rest, t = 0. */
int poursim_reset(poursim_world_t *world, uint32_t seed);

/* One dt step commanding torque a·tau_max, a in [-1, 1] (clamped), to the drive: it acts after
 * command_latency_ticks steps, within the drive's peak and torque–speed line, against its friction and
 * with its rotor inertia (docs/simulator.md, "The rig"); fills *out (may be NULL).
 * POURSIM_ENUMERIC if the liquid blew up in this step (a non-finite or runaway particle): the world is
 * then unusable until reset, and poursim_world_error() says which particle and where. */
int poursim_step(poursim_world_t *world, double action, poursim_obs_t *out);

/* Engages (1) or releases (0) the holding brake on the bucket's axis, for the steps that follow: a
 * friction brake that stops the axis and holds it against up to brake_torque, as the joint's motor at
 * zero speed with that torque limit (plus the drive's friction_coulomb, which uses the same motor). Torque
 * from poursim_step still acts on top. */
int poursim_set_brake(poursim_world_t *world, int engaged);

/* One dt step with the bucket driven toward theta_ref [rad] by a stiff servo (the joint's motor) instead
 * of a torque: for measurements that need a prescribed tilt (retention curve, sloshing). */
int poursim_step_servo(poursim_world_t *world, double theta_ref, poursim_obs_t *out);

/* The full drive's peaks and faults since the last reset (docs/motor.md). */
int poursim_drive_telemetry(const poursim_world_t *world, poursim_drive_telemetry_t *out);

/* The reason of the last failed step, "" if none. */
const char *poursim_world_error(const poursim_world_t *world);

/* The liquid's state right now: largest density over rest density (compression, fluid only) [-]. */
double poursim_max_density_ratio(const poursim_world_t *world);

/* The state after the last step (or reset). */
void poursim_observe(const poursim_world_t *world, poursim_obs_t *out);

void poursim_destroy(poursim_world_t *world);

const poursim_config_t *poursim_world_config(const poursim_world_t *world);

/* The config of the current episode: the world's config with the rand_* draws of the last reset's seed
 * applied (equal to poursim_world_config when every rand_* key is 0). */
const poursim_config_t *poursim_episode_config(const poursim_world_t *world);

/* Number of circles. */
int poursim_particle_count(const poursim_world_t *world);

/* Copies circle centres (x, y interleaved [m]) and radii [m]; either array may be NULL. Returns count. */
int poursim_particles(const poursim_world_t *world, float *xy, float *radius, int capacity);

/* Where each circle is: 0 rotating, 1 target, 2 spilled, 3 in flight. Returns count. */
int poursim_particle_regions(const poursim_world_t *world, uint8_t *region, int capacity);

/* Deepest circle–wall (and, for the pile, circle–circle) overlap right now [m] (contact quality). */
double poursim_max_overlap(const poursim_world_t *world);

/* Deepest any circle sank into a wall of either bucket since reset [m]: a contact sinks a fraction of a
 * millimetre; a circle that tunnels through a wall shows up as more than its radius. */
double poursim_max_wall_penetration(const poursim_world_t *world);


/* Running FNV-1a 64 over the bits of every observation and circle position so far (determinism). */
uint64_t poursim_trajectory_hash(const poursim_world_t *world);

/* ---- Whole-episode rollout with a float softmax-linear policy (the trainer's model). ---- */

/* The trainer's reward: r = k_target·V_target − k_spill·V_spill after each step, return Σ γ^t r_t. An
 * episode's figure (poursim_episode_t.ret, reward_sum), not part of the world. */
typedef struct {
  double k_target; /* >= 0 */
  double k_spill;  /* >= 0 */
  double gamma;    /* per-step discount, in [0, 1] */
} poursim_reward_t;

/* host_sim's reward for its figures: k_target 1, k_spill 5, gamma 0.9995 (the trainer sets its own). */
poursim_reward_t poursim_default_reward(void);

/* POURSIM_EINVAL, naming the field, unless every field is finite and in its range. */
int poursim_reward_validate(const poursim_reward_t *reward, char *err, size_t err_len);

/* Sets k_target, k_spill or gamma from text (host_sim --set); POURSIM_EINVAL for another key or a value out
 * of range, POURSIM_EPARSE for one that is not a number; *reward unchanged on error. */
int poursim_reward_set(poursim_reward_t *reward, const char *key, const char *value, char *err, size_t err_len);

/* A policy as weights.h describes it, in float: logits = x·W, x = [θn, ωn, Vr, Vt, Vs, 1]. */
typedef struct {
  int n_actions;              /* 2..POURSIM_MAX_ACTIONS */
  int decision_period;        /* steps between decisions, >= 1 */
  const double *w;            /* [POURSIM_N_FEATURES][n_actions], row-major */
  const double *levels;       /* [n_actions] torque fraction of tau_max, in [-1, 1] */
  double theta_min, theta_max; /* normalisation [rad] */
  double omega_max;            /* [rad/s] */
  int greedy;                 /* 1: argmax (ties to lowest index); 0: sample with the seed */
  poursim_reward_t reward;    /* the rollout's reward and return */
  double k_reversal;          /* training's reward shaping: cost of each torque reversal (0: none) */
} poursim_policy_t;

/* The policy's features, the float normalisation of docs/weights-h.md: x = [clip((θ − θmin)/(θmax − θmin)),
 * clip((θ̇ + ωmax)/(2ωmax)), clip(V_rotating), clip(V_target), clip(V_spill), 1], clip to [0, 1], with the
 * policy's theta_min, theta_max [rad] and omega_max [rad/s]. */
void poursim_features(const poursim_policy_t *policy, double theta, double omega, double v_rotating,
                      double v_target, double v_spill, double x[POURSIM_N_FEATURES]);

/* Caller-provided arrays; any pointer may be NULL. Capacities: decisions = ceil(steps / period). */
typedef struct {
  int capacity;         /* decisions the arrays hold */
  double *features;     /* [capacity][POURSIM_N_FEATURES] */
  int32_t *actions;     /* [capacity] */
  double *rewards;      /* [capacity] reward summed over the decision's steps */
  double *probs;        /* [capacity][n_actions] */
  int step_capacity;    /* steps the per-step arrays hold */
  double *step_rewards; /* [step_capacity] */
  double *step_theta;   /* [step_capacity] θ after each step [rad] */
  double *step_torque;  /* [step_capacity] the core's torque command of each step, fraction of tau_max */
} poursim_rollout_buffers_t;

/* Metrics of one episode. */
typedef struct {
  int n_steps;
  int n_decisions;
  double poured;       /* final V_target */
  double spilled;      /* final V_spill */
  double remaining;    /* final V_rotating */
  double finish_time;  /* first t at which V_target + V_spill reached 99 % of its final value [s];
                          -1 if it ends below 1 % (nothing poured) */
  double ret;          /* Σ γ^t r_t */
  double reward_sum;   /* Σ r_t */
  double max_theta;    /* [rad] */
  double liquid_l;     /* the episode's fill [L] (its config's fill_depth in a round bucket) */
  double peak_omega;   /* max |θ̇| [rad/s] */
  double peak_alpha;   /* max |θ̈|, θ̇ differenced over 10 ms [rad/s²] */
  int reversals;       /* sign changes of the commanded torque beyond ±1 N·m */
  int faults;          /* the firmware core's latched POUR_FAULT_* bits at the end (0: it never faulted) */
  int fault_step;      /* the step whose sample first found the core faulted, -1 if none */
} poursim_episode_t;

/* Resets the world with seed, runs one full episode through the firmware's pipeline (its default config,
 * the rig's encoder): each step's sensor sample goes through the core's estimator and supervisor; at steps
 * 0, P, 2P, … of its RUN the policy picks an action from the state the core estimated; the level goes
 * through the core's envelope, or its controlled stop and brake once it faults (episode->faults). */
int poursim_rollout(poursim_world_t *world, const poursim_policy_t *policy, uint32_t seed,
                    const poursim_rollout_buffers_t *buffers, poursim_episode_t *episode);

/* n rollouts with seeds[i], on n_threads threads (each with its own world). bufs and episodes are
 * arrays of n (bufs may be NULL). */
int poursim_rollout_batch(const poursim_config_t *config, const poursim_policy_t *policy,
                          const uint32_t *seeds, int n, int n_threads,
                          const poursim_rollout_buffers_t *bufs, poursim_episode_t *episodes,
                          char *err, size_t err_len);

/* A torque fraction of tau_max as the firmware's Q15 command: the host's one rule, which Python's
 * pour.policy.fixedpoint.float_to_q15 follows too. Rounds half up (floor(32768 x + 1/2)), as the firmware
 * rounds; saturates to [-32768, 32767] (+1.0 -> 32767, -1.0 -> -32768, +-inf to the limits); NaN -> 0 (no
 * torque, never a plausible command). */
int16_t poursim_fraction_to_q15(double fraction);

/* sizeof the named plain record of the C API ("poursim_obs_t", ..., "poursim_weights_file_t"), 0 if unknown:
 * Python's ctypes mirrors are checked against it. */
size_t poursim_sizeof(const char *type_name);

/* Library version string. */
const char *poursim_version(void);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_POURSIM_H */
