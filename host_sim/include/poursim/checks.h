/* SPDX-License-Identifier: MIT */
/* Physical checks of the simulated liquid and rig against independent references: hydrostatics (an ideal
 * liquid's retention curve, a resting liquid's weight), linear sloshing theory (the first mode of a
 * rectangular tank), momentum (the stream's impact), Newton's second law and the drive's datasheet line. The
 * benchmark prints them, the tests pin them, pour-plots draws them (docs/simulator.md). */
#ifndef POURSIM_CHECKS_H
#define POURSIM_CHECKS_H

#include <stddef.h>
#include <stdint.h>

#include "poursim/poursim.h"

#ifdef __cplusplus
extern "C" {
#endif

#define POURSIM_RETENTION_MAX 181 /* samples of a retention curve: 0°, 1°, …, 180° */

/* The share of its liquid a rectangular bucket keeps when tilted by theta [rad] if the liquid stays
 * level: min(A, area of the cross-section below the horizontal line through the lower lip) / A, with
 * A = width·fill_depth. width, depth: inner section [m]; fill_depth: upright fill [m]. */
double poursim_ideal_retained(double width, double depth, double fill_depth, double theta);

/* First mode of a rectangular tank of width L and liquid depth h: ω² = (gπ/L)·tanh(πh/L) [Hz]. */
double poursim_slosh_theory_hz(double width, double fill_depth);

typedef struct {
  int n;                                 /* samples, one per degree from 0 */
  double theta[POURSIM_RETENTION_MAX];   /* [rad] */
  double kept[POURSIM_RETENTION_MAX];    /* V_rotating when the tilt passes theta, mean over the seeds [-] */
  double ideal[POURSIM_RETENTION_MAX];   /* poursim_ideal_retained at theta [-] */
  double onset;                          /* first theta with kept <= 99.5 % [rad]; -1 if never */
  double ideal_onset;                    /* the same for the ideal liquid [rad] */
  double rms_gap;                        /* RMS of kept − ideal over the samples [-] */
} poursim_retention_t;

/* Tilts the bucket by servo at rate [rad/s] from upright to theta_end [rad] and records what it keeps,
 * once for each of the seeds seed, seed + 1, …, seed + n_seeds − 1 (one particle is 0.7 % of the liquid:
 * the mean of a few seeds is a smoother curve). */
int poursim_measure_retention(const poursim_config_t *config, uint32_t seed, int n_seeds, double rate,
                              double theta_end, poursim_retention_t *out, char *err, size_t err_len);

typedef struct {
  double freq;        /* natural frequency of the liquid's centre of mass across the bucket [Hz] */
  double freq_theory; /* poursim_slosh_theory_hz of the fill [Hz] */
  double damping;     /* damping ratio [-] */
  double amplitude;   /* of the wave at the end of the tilt [m] */
  double noise;       /* RMS of the centre of mass over the last half of the hold (the agitation) [m] */
  int n;              /* samples written to trace */
} poursim_slosh_t;

/* Tilts the bucket by servo to tilt [rad] at a constant rate over ramp_s [s], holds it hold_s [s], and
 * analyses the liquid's centre of mass across the bucket (in its frame) during the hold, averaged over
 * the seeds seed … seed + n_seeds − 1: the slosh is the same in each, the agitation is not, so the mean
 * keeps the wave and loses the noise. trace (may be NULL) receives the mean, one sample a step, up to
 * trace_cap. */
int poursim_measure_slosh(const poursim_config_t *config, uint32_t seed, int n_seeds, double tilt, double ramp_s,
                          double hold_s, double *trace, int trace_cap, poursim_slosh_t *out, char *err,
                          size_t err_len);

/* ---- The rig: the drive and the sensors against their references (docs/simulator.md, "The rig"). ---- */

#define POURSIM_FRICTION_SPEEDS 5 /* steady speeds of the friction sweep: 0.2, 0.5, 1, 1.5, 2 rad/s */

typedef struct {
  int latency_ticks;           /* steps from the call that commands torque to the first step the bucket moves */
  double inertia_measured;     /* Σ net torque / Σ α over a spin-up from rest at upright [kg·m²] */
  double inertia_expected;     /* the U of three boxes about the pivot, by hand, + J·N² [kg·m²] */
  double inertia_bucket;       /* the U alone [kg·m²] */
  double breakaway_torque;     /* delivered torque when the bucket first moves, slow ramp from rest [N·m] */
  double terminal_load[2];     /* Coulomb friction of the two free-spin runs (the config's, and 10 N·m) [N·m] */
  double terminal_speed[2];    /* full command, no stops, mean speed over the last second of 1.5 s [rad/s] */
  double terminal_expected[2]; /* the datasheet line: ω₀·(1 − (τ_c + b·ω)/τ_peak), solved for ω [rad/s] */
  double friction_speed[POURSIM_FRICTION_SPEEDS];    /* mean speed over the span, held by a speed loop [rad/s] */
  double friction_measured[POURSIM_FRICTION_SPEEDS]; /* mean of τ_delivered − G·sinθ − J·α over it [N·m] */
  double friction_expected[POURSIM_FRICTION_SPEEDS]; /* F_c + b·ω at that speed [N·m] */
} poursim_drive_check_t;

/* Runs the drive on the empty bucket (the liquid taken out) of config: latency, reflected inertia,
 * Coulomb breakaway, terminal speeds on the torque–speed line, and the friction torque at steady speeds. */
int poursim_measure_drive(const poursim_config_t *config, poursim_drive_check_t *out, char *err, size_t err_len);

typedef struct {
  double encoder_max_error;    /* max |count − θ·2^bits/2π| (wrapped) over a swing from the lower stop [counts] */
  uint32_t encoder_at_stop;    /* the count at the lower stop (below upright: just under 2^bits) */
  double liquid_g;             /* the liquid's mass [g] */
  double rest_rotating_g;      /* mean rotating reading, full bucket held upright, 1 s [g] */
  double target_liquid_g;      /* V_target × the liquid's mass, after the pour settled [g] */
  double rest_target_g;        /* mean target reading then, 1 s [g] */
  double update_rate_hz;       /* conversions per second during the pour (from the intervals between changes) */
  double delay_s;              /* the span over which the every-step reference, averaged, gives the conversions [s] */
  double delay_match;          /* share of the conversions within a resolution of that mean */
  double noise_rms_g;          /* RMS of noisy − noise-free conversions, same seed [g] */
  double noise_expected_g;     /* that RMS for Gaussian noise of scale_noise_g quantised to scale_resolution_g [g] */
  double impact_impulse_gs;    /* ∫(target reading − mass inside the target) dt over the pour [g·s] */
  double impact_expected_gs;   /* Σ m·v_down of particles entering the target, minus leaving, / g [g·s] */
  double impact_peak_g;        /* largest impact term (50 ms mean) during the pour [g] */
  double impact_peak_reading_g; /* the target reading at that moment [g] */
  int hash_unchanged;          /* 1: noise, lag and rate of the scales left the trajectory hash as it was */
} poursim_sensor_check_t;

/* Pours with the servo (held upright 1 s, tilted at 0.5 rad/s to 125°, held 3 s) in three worlds of the
 * same seed: the sensors of config, the same without noise, and an every-step unfiltered noise-free
 * reference; compares them, and the readings against the liquid's mass and momentum. */
int poursim_measure_sensors(const poursim_config_t *config, uint32_t seed, poursim_sensor_check_t *out, char *err,
                            size_t err_len);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_CHECKS_H */
