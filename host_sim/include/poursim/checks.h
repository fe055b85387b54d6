/* SPDX-License-Identifier: MIT */
/* Physical checks of the simulated liquid against independent references: hydrostatics (an ideal
 * liquid's retention curve) and linear sloshing theory (the first mode of a rectangular tank). The
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

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_CHECKS_H */
