/* SPDX-License-Identifier: MIT */
/* The liquid against physics: retention against hydrostatics, sloshing against linear wave theory, a
 * fluid that blows up is stopped, any particle count up to 1,000 works, and its config is checked.
 * Figures and bars as in docs/simulator.md; the same measurements print in host_sim --bench. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "poursim/checks.h"
#include "poursim/poursim.h"
#include "unity.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static poursim_config_t cfg;
static char err[POURSIM_ERR_LEN];

void setUp(void) {
  cfg = poursim_default_config();
  err[0] = '\0';
}

void tearDown(void) {}

static poursim_retention_t retention_at(const poursim_config_t *c, double fill_share, int seeds) {
  poursim_config_t cc = *c;
  cc.fill_depth = fill_share * (cc.bucket_height - cc.bucket_wall);
  poursim_retention_t r;
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_measure_retention(&cc, 1, seeds, 0.02, 125 * DEG, &r, err, sizeof err),
                                err);
  printf("fill %.0f %%, fluid %d: onset %.0f deg (ideal %.0f), RMS gap %.1f %%\n", 100 * fill_share, cc.fluid,
         r.onset / DEG, r.ideal_onset / DEG, 100 * r.rms_gap);
  return r;
}

static void test_liquid_IdealRetentionMatchesHandGeometry(void) {
  /* 24 × 32.5 cm, 22.1 cm of liquid: upright all of it; the surface reaches the lip at
   * tan θ = 2(D − h)/w (41.6°); at 90° nothing; half out where the triangle holds half. */
  const double w = 0.24, d = 0.325, h = 0.221;
  TEST_ASSERT_EQUAL_DOUBLE(1.0, poursim_ideal_retained(w, d, h, 0.0));
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.0, poursim_ideal_retained(w, d, h, atan(2 * (d - h) / w) - 1e-6));
  TEST_ASSERT_TRUE(poursim_ideal_retained(w, d, h, atan(2 * (d - h) / w) + 0.01) < 1.0);
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, poursim_ideal_retained(w, d, h, 90 * DEG));
  /* Past the bucket-bottom corner the kept part is a triangle with legs d and d·tan(90° − θ). */
  double th = 70 * DEG, tri = 0.5 * d * d * tan(PI / 2 - th) / (w * h);
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, tri, poursim_ideal_retained(w, d, h, th));
  TEST_ASSERT_DOUBLE_WITHIN(0.005, 1.80, poursim_slosh_theory_hz(0.24, 0.22));
}

static void test_liquid_RetentionFollowsHydrostaticsAtEveryFill(void) {
  const double fills[3] = {0.60, 0.70, 0.85};
  for (int k = 0; k < 3; ++k) {
    poursim_retention_t r = retention_at(&cfg, fills[k], 3);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(5 * DEG, r.ideal_onset, r.onset, "onset more than 5 deg from the ideal");
    TEST_ASSERT_TRUE_MESSAGE(r.rms_gap <= 0.05, "RMS gap to the ideal curve above 5 % of the liquid");
  }
}

static void test_liquid_WithTheFluidLayerOffThePileJamsAndFailsTheSameBars(void) {
  cfg.fluid = 0;
  poursim_retention_t r = retention_at(&cfg, 0.70, 1);
  TEST_ASSERT_TRUE_MESSAGE(r.onset - r.ideal_onset > 10 * DEG, "the rigid pile should pour late");
  TEST_ASSERT_TRUE_MESSAGE(r.rms_gap > 0.10, "the rigid pile should miss the ideal curve");
}

static void test_liquid_SloshesAtTheFirstModeOfARectangularTankAndDecays(void) {
  poursim_slosh_t s;
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK,
                                poursim_measure_slosh(&cfg, 1, 16, 12 * DEG, 0.3, 4.0, NULL, 0, &s, err, sizeof err), err);
  printf("slosh: %.3f Hz (theory %.3f), damping ratio %.3f, amplitude %.2f mm, noise %.2f mm\n", s.freq,
         s.freq_theory, s.damping, 1e3 * s.amplitude, 1e3 * s.noise);
  TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.15 * s.freq_theory, s.freq_theory, s.freq, "slosh frequency off theory by > 15 %");
  TEST_ASSERT_TRUE_MESSAGE(s.damping > 0.0 && s.damping < 0.5, "the wave should decay, and oscillate while it does");
  TEST_ASSERT_TRUE_MESSAGE(s.amplitude > 3.0 * s.noise, "the wave should stand out of the agitation");
}

static void test_liquid_ABlownUpFluidStopsTheStepWithAClearError(void) {
  cfg.fluid_stiffness = 1e5; /* stable at 1 ms, not at 5 ms */
  cfg.dt = 0.005;
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  int rc = POURSIM_OK, steps = 0;
  while (rc == POURSIM_OK && steps < 2000) rc = poursim_step(w, 0.5, NULL), ++steps;
  TEST_ASSERT_EQUAL_INT(POURSIM_ENUMERIC, rc);
  TEST_ASSERT_NOT_NULL(strstr(poursim_world_error(w), "blew up"));
  TEST_ASSERT_NOT_NULL(strstr(poursim_world_error(w), "particle"));
  /* The world refuses to go on until it is reset; a reset brings it back. */
  TEST_ASSERT_NOT_EQUAL(POURSIM_OK, poursim_step(w, 0.0, NULL));
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_reset(w, 1));
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_step(w, 0.0, NULL));
  TEST_ASSERT_EQUAL_STRING("", poursim_world_error(w));
  poursim_destroy(w);
}

static void test_liquid_AThousandParticlesPourAndAreAllAccountedFor(void) {
  cfg.n_particles = 1000;
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  poursim_obs_t o;
  for (int t = 0; t < 1500; ++t) TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_step_servo(w, 1.6 * t / 1500.0, &o));
  TEST_ASSERT_EQUAL_INT(1000, poursim_particle_count(w));
  TEST_ASSERT_TRUE(o.v_rotating < 0.9); /* it poured */
  TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0, o.v_rotating + o.v_target + o.v_spill + o.v_flight);
  poursim_destroy(w);
}

static void expect_refused(const char *key, const char *value, const char *named) {
  poursim_config_t c = poursim_default_config();
  int rc = poursim_config_set(&c, key, value, err, sizeof err);
  if (rc == POURSIM_OK) rc = poursim_config_validate(&c, err, sizeof err);
  char msg[POURSIM_ERR_LEN + 64];
  snprintf(msg, sizeof msg, "%s = %s: '%s'", key, value, err);
  TEST_ASSERT_NOT_EQUAL_MESSAGE(POURSIM_OK, rc, msg);
  TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, named), msg);
}

static void test_liquid_BadLiquidConfigIsRefusedNamingTheKey(void) {
  expect_refused("fill_depth", "0.32", "fill_depth");       /* overflows the 32.5 cm bucket */
  expect_refused("fill_depth", "nan", "fill_depth");
  expect_refused("n_particles", "3", "n_particles");        /* spacing wider than half the bucket */
  expect_refused("n_particles", "1025", "n_particles");     /* above POURSIM_MAX_PARTICLES */
  expect_refused("n_particles", "1", "n_particles");
  expect_refused("fluid", "2", "fluid");
  expect_refused("fluid_smoothing", "0.5", "fluid_smoothing");
  expect_refused("fluid_contact_radius", "0.9", "fluid_contact_radius");
  expect_refused("fluid_stiffness", "-1", "fluid_stiffness");
  expect_refused("fluid_viscosity", "inf", "fluid_viscosity");
  expect_refused("fluid_agitation", "9", "fluid_agitation");
  expect_refused("liquid_density", "0", "liquid_density");
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_liquid_IdealRetentionMatchesHandGeometry);
  RUN_TEST(test_liquid_RetentionFollowsHydrostaticsAtEveryFill);
  RUN_TEST(test_liquid_WithTheFluidLayerOffThePileJamsAndFailsTheSameBars);
  RUN_TEST(test_liquid_SloshesAtTheFirstModeOfARectangularTankAndDecays);
  RUN_TEST(test_liquid_ABlownUpFluidStopsTheStepWithAClearError);
  RUN_TEST(test_liquid_AThousandParticlesPourAndAreAllAccountedFor);
  RUN_TEST(test_liquid_BadLiquidConfigIsRefusedNamingTheKey);
  return UNITY_END();
}
