/* SPDX-License-Identifier: MIT */
/* libpoursim's rig: the drive (latency, reflected inertia, Coulomb friction, torque–speed line), the
 * sensors (encoder, load cells: weight, rate, lag, noise, the stream's impact) and domain randomisation,
 * each against its reference, and each new config key refused by name. Every check would fail with its
 * effect switched off: the expected values contain the effect (J·N², the friction, the back-EMF line,
 * the lag, ṁ·v). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "poursim/checks.h"
#include "poursim/poursim.h"
#include "unity.h"

static poursim_config_t cfg;
static char err[POURSIM_ERR_LEN];

void setUp(void) {
  cfg = poursim_default_config();
  err[0] = '\0';
}

void tearDown(void) {}

static poursim_drive_check_t drive(const poursim_config_t *c) {
  poursim_drive_check_t d;
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_measure_drive(c, &d, err, sizeof err), err);
  return d;
}

static poursim_sensor_check_t sensors(const poursim_config_t *c) {
  poursim_sensor_check_t s;
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_measure_sensors(c, 1, &s, err, sizeof err), err);
  return s;
}

static void test_rig_CommandActsExactlyLatencyTicksLater(void) {
  TEST_ASSERT_EQUAL_INT(1, drive(&cfg).latency_ticks);
  cfg.command_latency_ticks = 4;
  TEST_ASSERT_EQUAL_INT(4, drive(&cfg).latency_ticks);
}

/* Newton: α = τ_net / (J_U + J_rotor·N²), J_U the three boxes by hand. */
static void test_rig_SpinUpMeasuresTheReflectedRotorInertia(void) {
  poursim_drive_check_t d = drive(&cfg);
  printf("inertia: measured %.5f, expected %.5f (U alone %.5f) kg m^2\n", d.inertia_measured, d.inertia_expected,
         d.inertia_bucket);
  TEST_ASSERT_DOUBLE_WITHIN(0.01 * d.inertia_expected, d.inertia_expected, d.inertia_measured);
  TEST_ASSERT_TRUE(d.inertia_measured > 1.1 * d.inertia_bucket); /* the rotor's share is visible */
  cfg.motor_rotor_inertia = 0.0;
  d = drive(&cfg);
  TEST_ASSERT_DOUBLE_WITHIN(0.01 * d.inertia_bucket, d.inertia_bucket, d.inertia_measured);
}

static void test_rig_CoulombFrictionHoldsUntilTheTorqueExceedsIt(void) {
  poursim_drive_check_t d = drive(&cfg);
  TEST_ASSERT_DOUBLE_WITHIN(0.02, cfg.friction_coulomb, d.breakaway_torque);
  cfg.friction_coulomb = 2.5;
  d = drive(&cfg);
  TEST_ASSERT_DOUBLE_WITHIN(0.02, 2.5, d.breakaway_torque);
}

/* The datasheet line: at full command the speed settles where the available torque meets the load. */
static void test_rig_TerminalSpeedsLieOnTheTorqueSpeedLine(void) {
  poursim_drive_check_t d = drive(&cfg);
  for (int r = 0; r < 2; ++r) {
    printf("terminal speed, Coulomb %.1f N m: %.3f rad/s, line %.3f rad/s\n", d.terminal_load[r], d.terminal_speed[r],
           d.terminal_expected[r]);
    TEST_ASSERT_DOUBLE_WITHIN(0.01 * d.terminal_expected[r], d.terminal_expected[r], d.terminal_speed[r]);
  }
  TEST_ASSERT_TRUE(d.terminal_speed[0] < cfg.motor_no_load_speed);
  TEST_ASSERT_TRUE(d.terminal_speed[1] < 0.65 * cfg.motor_no_load_speed); /* the load slows it down the line */
}

/* Friction at steady speed, by Newton on the empty bucket, is what its keys say: F_c + b·ω from 0.2 to
 * 2 rad/s, for the default and for a stiffer and a lighter axis. 2 mN·m is 0.3 % of F_c, b·ω at 0.1 rad/s. */
static void test_rig_SteadyFrictionIsCoulombPlusViscous(void) {
  const double coulomb[3] = {0.6, 1.2, 0.3}, viscous[3] = {0.02, 0.05, 0.01};
  for (int v = 0; v < 3; ++v) {
    cfg.friction_coulomb = coulomb[v];
    cfg.friction_viscous = viscous[v];
    poursim_drive_check_t d = drive(&cfg);
    for (int r = 0; r < POURSIM_FRICTION_SPEEDS; ++r) {
      printf("F_c %.2f, b %.3f: at %.3f rad/s friction %.4f N m, F_c + b w %.4f N m\n", coulomb[v], viscous[v],
             d.friction_speed[r], d.friction_measured[r], d.friction_expected[r]);
      TEST_ASSERT_DOUBLE_WITHIN(0.002, d.friction_expected[r], d.friction_measured[r]);
    }
    TEST_ASSERT_DOUBLE_WITHIN(0.02, 0.2, d.friction_speed[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.02, 2.0, d.friction_speed[POURSIM_FRICTION_SPEEDS - 1]);
  }
}

static void test_rig_SensorsAgainstMassMomentumAndTheirConfig(void) {
  poursim_sensor_check_t s = sensors(&cfg);
  printf("encoder max error %.4f counts, at the lower stop %u; rotating at rest %.1f g of %.1f g; target %.1f g of "
         "%.1f g; %.2f conversions/s, filter span %.4f s (%.3f match); noise %.3f g (expected %.3f g); impact %.1f g s "
         "(momentum %.1f g s), peak %.0f g on a reading of %.0f g\n",
         s.encoder_max_error, s.encoder_at_stop, s.rest_rotating_g, s.liquid_g, s.rest_target_g, s.target_liquid_g,
         s.update_rate_hz, s.delay_s, s.delay_match, s.noise_rms_g, s.noise_expected_g, s.impact_impulse_gs,
         s.impact_expected_gs, s.impact_peak_g, s.impact_peak_reading_g);
  /* Encoder: rounding to the nearest count; below upright it wraps to just under 2^17 (the stop is -5°). */
  TEST_ASSERT_TRUE(s.encoder_max_error <= 0.5 + 1e-6);
  TEST_ASSERT_UINT32_WITHIN(2, (1u << 17) - 1820u, s.encoder_at_stop);
  /* Hydrostatics: a resting liquid weighs its mass, on either cell. */
  TEST_ASSERT_DOUBLE_WITHIN(0.01 * s.liquid_g, s.liquid_g, s.rest_rotating_g);
  TEST_ASSERT_TRUE(s.target_liquid_g > 0.9 * s.liquid_g);
  TEST_ASSERT_DOUBLE_WITHIN(0.01 * s.target_liquid_g, s.target_liquid_g, s.rest_target_g);
  /* 80 conversions a second, each the mean load of the 50 ms before it, exactly. */
  TEST_ASSERT_DOUBLE_WITHIN(0.5, 80.0, s.update_rate_hz);
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.05, s.delay_s);
  TEST_ASSERT_TRUE(s.delay_match > 0.99);
  /* Momentum: what the scale reads beyond the liquid inside is the momentum the stream brings in. */
  TEST_ASSERT_TRUE(s.impact_expected_gs > 500.0);
  TEST_ASSERT_DOUBLE_WITHIN(0.1 * s.impact_expected_gs, s.impact_expected_gs, s.impact_impulse_gs);
  TEST_ASSERT_TRUE(s.hash_unchanged);
}

/* Another rate, lag and noise: the measurements follow the config, not constants. */
static void test_rig_ScaleRateLagAndNoiseFollowTheConfig(void) {
  cfg.scale_rate_hz = 50.0;
  cfg.scale_delay_s = 0.02;
  cfg.scale_noise_g = 5.0;
  poursim_sensor_check_t s = sensors(&cfg);
  printf("50 Hz, 20 ms, 5 g: %.2f conversions/s, filter span %.4f s (%.3f), noise %.3f g (expected %.3f g)\n", s.update_rate_hz,
         s.delay_s, s.delay_match, s.noise_rms_g, s.noise_expected_g);
  TEST_ASSERT_DOUBLE_WITHIN(0.5, 50.0, s.update_rate_hz);
  TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.02, s.delay_s);
  TEST_ASSERT_TRUE(s.delay_match > 0.99);
  TEST_ASSERT_DOUBLE_WITHIN(0.1 * s.noise_expected_g, s.noise_expected_g, s.noise_rms_g);
  TEST_ASSERT_TRUE(s.noise_expected_g > 5.0);
  TEST_ASSERT_TRUE(s.hash_unchanged); /* noise, lag and rate leave the physics alone */
}

/* The readings a step reports: deterministic per seed, and noise changes them but not the trajectory. */
static void test_rig_NoiseIsSeededAndLeavesTheTrajectory(void) {
  cfg.scale_noise_g = 3.0;
  poursim_config_t quiet = cfg;
  quiet.scale_noise_g = 0.0;
  poursim_world_t *a = poursim_create(&cfg, err, sizeof err), *b = poursim_create(&cfg, err, sizeof err);
  poursim_world_t *q = poursim_create(&quiet, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(a && b && q, err);
  poursim_obs_t oa, ob, oq;
  int differ = 0;
  for (int t = 0; t < 1500; ++t) {
    double act = 0.8 * sin(t * 0.004) + 0.2;
    poursim_step(a, act, &oa);
    poursim_step(b, act, &ob);
    poursim_step(q, act, &oq);
    TEST_ASSERT_EQUAL_INT32(oa.scale_rotating_g, ob.scale_rotating_g);
    TEST_ASSERT_EQUAL_INT32(oa.scale_target_g, ob.scale_target_g);
    TEST_ASSERT_EQUAL_UINT32(oa.encoder, oq.encoder);
    TEST_ASSERT_EQUAL_DOUBLE(oa.theta, oq.theta);
    differ += oa.scale_rotating_g != oq.scale_rotating_g;
  }
  TEST_ASSERT_TRUE(differ > 50);
  TEST_ASSERT_TRUE(poursim_trajectory_hash(a) == poursim_trajectory_hash(q));
  poursim_destroy(a);
  poursim_destroy(b);
  poursim_destroy(q);
}

/* The drive limits what it delivers: the peak, and nothing in the motoring quadrant at the no-load speed. */
static void test_rig_DeliveredTorqueIsClampedToThePeak(void) {
  cfg.tau_max = 40.0; /* commands beyond the drive's 25 N·m */
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  poursim_obs_t o;
  poursim_step(w, 1.0, &o);
  TEST_ASSERT_EQUAL_DOUBLE(0.0, o.motor_torque); /* latency: nothing yet */
  TEST_ASSERT_EQUAL_DOUBLE(40.0, o.torque);
  poursim_step(w, 1.0, &o);
  TEST_ASSERT_DOUBLE_WITHIN(0.01, cfg.motor_peak_torque, o.motor_torque); /* at rest: the peak */
  for (int t = 0; t < 100; ++t) {
    const double omega = o.omega; /* the speed the step starts from */
    poursim_step(w, 1.0, &o);
    /* at speed, the line */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, cfg.motor_peak_torque * (1.0 - omega / cfg.motor_no_load_speed), o.motor_torque);
  }
  TEST_ASSERT_TRUE(o.omega > 2.0); /* far enough down the line to tell */
  poursim_destroy(w);
}

static void test_rig_RandomisationDrawsWithinItsRangesFromTheSeed(void) {
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  TEST_ASSERT_EQUAL_MEMORY(&cfg, poursim_episode_config(w), sizeof cfg); /* off by default */
  poursim_destroy(w);
  cfg.rand_fill = 0.2;
  cfg.rand_target_dx = 0.02;
  cfg.rand_pivot_height = 0.02;
  cfg.rand_motor = 0.15;
  cfg.rand_bucket_mass = 0.2;
  cfg.rand_liquid = 0.2;
  cfg.rand_sensor = 0.5;
  w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  double lo_fill = 1, hi_fill = 0, lo_dx = 1, hi_dx = 0;
  int latency2 = 0;
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_reset(w, seed));
    const poursim_config_t e = *poursim_episode_config(w);
    TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_config_validate(&e, err, sizeof err), err);
    TEST_ASSERT_TRUE(fabs(e.fill_depth / cfg.fill_depth - 1.0) <= 0.2);
    TEST_ASSERT_TRUE(fabs(e.target_dx - cfg.target_dx) <= 0.02 && fabs(e.pivot_height - cfg.pivot_height) <= 0.02);
    TEST_ASSERT_TRUE(fabs(e.motor_peak_torque / cfg.motor_peak_torque - 1.0) <= 0.15);
    TEST_ASSERT_TRUE(fabs(e.motor_rotor_inertia / cfg.motor_rotor_inertia - 1.0) <= 0.15);
    TEST_ASSERT_TRUE(fabs(e.bucket_mass / cfg.bucket_mass - 1.0) <= 0.2);
    TEST_ASSERT_TRUE(fabs(e.liquid_density / cfg.liquid_density - 1.0) <= 0.2);
    TEST_ASSERT_TRUE(fabs(e.scale_delay_s / cfg.scale_delay_s - 1.0) <= 0.5);
    TEST_ASSERT_TRUE(e.command_latency_ticks == 1 || e.command_latency_ticks == 2);
    latency2 += e.command_latency_ticks == 2;
    lo_fill = fmin(lo_fill, e.fill_depth / cfg.fill_depth), hi_fill = fmax(hi_fill, e.fill_depth / cfg.fill_depth);
    lo_dx = fmin(lo_dx, e.target_dx - cfg.target_dx), hi_dx = fmax(hi_dx, e.target_dx - cfg.target_dx);
    /* The world is built from the draw: held upright, the liquid weighs the drawn mass on the rotating cell. */
    if (seed > 10) continue;
    poursim_obs_t o;
    double sum_g = 0;
    for (int t = 0; t < 1000; ++t) {
      poursim_step_servo(w, 0.0, &o);
      sum_g += o.scale_rotating_g;
    }
    const double r = 0.5 * e.bucket_inner_width;
    double mass_g = 1000.0 * e.liquid_density * e.fill_depth * 3.14159265358979323846 * r * r;
    /* the agitated liquid's weight fluctuates (docs/simulator.md): 1 s mean within 5 % */
    TEST_ASSERT_DOUBLE_WITHIN(0.05 * mass_g, mass_g, sum_g / 1000);
  }
  /* Spread over the range, both latencies drawn. */
  TEST_ASSERT_TRUE(lo_fill < 0.9 && hi_fill > 1.1 && lo_dx < -0.01 && hi_dx > 0.01);
  TEST_ASSERT_TRUE(latency2 > 5 && latency2 < 35);
  /* The same seed draws the same episode. */
  poursim_reset(w, 7);
  poursim_config_t first = *poursim_episode_config(w);
  poursim_reset(w, 8);
  poursim_reset(w, 7);
  TEST_ASSERT_EQUAL_MEMORY(&first, poursim_episode_config(w), sizeof first);
  /* The world's own config stays as created. */
  TEST_ASSERT_EQUAL_DOUBLE(cfg.fill_depth, poursim_world_config(w)->fill_depth);
  poursim_destroy(w);
}

/* Draws that would make no valid world are drawn again: with the pivot low and the target close, a wide
 * randomisation of both would often put the target into the bucket's sweep. */
static void test_rig_InvalidDrawsAreDrawnAgain(void) {
  cfg.pivot_height = 0.53;
  cfg.rand_pivot_height = 0.1;
  cfg.rand_target_dx = 0.1;
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_config_validate(&cfg, err, sizeof err), err);
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  int moved = 0;
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_reset(w, seed));
    const poursim_config_t *e = poursim_episode_config(w);
    TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_config_validate(e, err, sizeof err), err);
    moved += e->pivot_height != cfg.pivot_height;
  }
  TEST_ASSERT_TRUE(moved > 25);
  poursim_destroy(w);
}

static void test_rig_EveryNewKeyIsRefusedByName(void) {
  static const char *const keys[] = {"motor_peak_torque", "motor_no_load_speed", "motor_rotor_inertia", "gear_ratio",
                                     "friction_coulomb", "friction_viscous", "command_latency_ticks", "encoder_bits",
                                     "scale_rate_hz", "scale_delay_s", "scale_noise_g", "scale_resolution_g",
                                     "rand_fill", "rand_target_dx", "rand_pivot_height", "rand_motor",
                                     "rand_bucket_mass", "rand_liquid", "rand_sensor"};
  for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k) {
    poursim_config_t c = poursim_default_config();
    TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_EINVAL, poursim_config_set(&c, keys[k], "-1", err, sizeof err), keys[k]);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, keys[k]), err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_EINVAL, poursim_config_set(&c, keys[k], "1e9", err, sizeof err), keys[k]);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "(unit: "), err);
    TEST_ASSERT_EQUAL_INT(POURSIM_EPARSE, poursim_config_set(&c, keys[k], "fast", err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, keys[k]), err);
  }
  poursim_config_t c = poursim_default_config();
  TEST_ASSERT_EQUAL_INT(POURSIM_EPARSE, poursim_config_set(&c, "command_latency_ticks", "1.5", err, sizeof err));
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_set(&c, "command_latency_ticks", "0", err, sizeof err));
  /* In a struct, too (validate), and across keys: no conversion faster than the step. */
  c.friction_viscous = NAN;
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_validate(&c, err, sizeof err));
  TEST_ASSERT_NOT_NULL(strstr(err, "friction_viscous"));
  c = poursim_default_config();
  c.scale_rate_hz = 2000.0;
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_validate(&c, err, sizeof err));
  TEST_ASSERT_NOT_NULL(strstr(err, "scale_rate_hz"));
  /* And in a file, with its line; a written config loads back with the new keys. */
  const char *path = "test_rig.cfg";
  FILE *f = fopen(path, "w");
  TEST_ASSERT_NOT_NULL(f);
  fputs("gear_ratio = 20\nrand_motor = 0.7\n", f);
  fclose(f);
  c = poursim_default_config();
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_load(path, &c, err, sizeof err));
  TEST_ASSERT_NOT_NULL(strstr(err, ":2:"));
  TEST_ASSERT_NOT_NULL(strstr(err, "rand_motor"));
  poursim_config_t a = poursim_default_config(), b = poursim_default_config();
  a.motor_rotor_inertia = 3.5e-5;
  a.command_latency_ticks = 3;
  a.rand_sensor = 0.25;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_write(&a, path, err, sizeof err));
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_load(path, &b, err, sizeof err));
  TEST_ASSERT_EQUAL_MEMORY(&a, &b, sizeof a);
  remove(path);
  /* --help's table: every key with its unit and range. */
  char text[8192];
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_describe(text, sizeof text));
  for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k)
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(text, keys[k]), keys[k]);
  TEST_ASSERT_NOT_NULL(strstr(text, "motor_no_load_speed    [rad/s at the output] 0.1..1000, default 21"));
  TEST_ASSERT_NOT_NULL(strstr(text, "command_latency_ticks  [steps] 1..100 (integer), default 1"));
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_describe(text, 100));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_rig_CommandActsExactlyLatencyTicksLater);
  RUN_TEST(test_rig_SpinUpMeasuresTheReflectedRotorInertia);
  RUN_TEST(test_rig_CoulombFrictionHoldsUntilTheTorqueExceedsIt);
  RUN_TEST(test_rig_TerminalSpeedsLieOnTheTorqueSpeedLine);
  RUN_TEST(test_rig_SteadyFrictionIsCoulombPlusViscous);
  RUN_TEST(test_rig_SensorsAgainstMassMomentumAndTheirConfig);
  RUN_TEST(test_rig_ScaleRateLagAndNoiseFollowTheConfig);
  RUN_TEST(test_rig_NoiseIsSeededAndLeavesTheTrajectory);
  RUN_TEST(test_rig_DeliveredTorqueIsClampedToThePeak);
  RUN_TEST(test_rig_RandomisationDrawsWithinItsRangesFromTheSeed);
  RUN_TEST(test_rig_InvalidDrawsAreDrawnAgain);
  RUN_TEST(test_rig_EveryNewKeyIsRefusedByName);
  return UNITY_END();
}
