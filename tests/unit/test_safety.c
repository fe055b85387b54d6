/* SPDX-License-Identifier: MIT */
/* The envelope's rules one by one (the torque rules with a speed band too wide to act, then the motion
 * envelope), and the motion envelope in closed loop with the estimator on a gravity-loaded bucket. */
#include "pour/safety.h"
#include "pour/sensors.h"
#include "unity.h"

static pour_safety_config_t config;
static pour_safety_t safety;

#define MID_URAD 1000000 /* well inside the angle limits */

/* The torque rules alone: a speed band of ±100 rad/s at rest lets any torque through. */
static void init_without_band(void) {
  config.omega_max_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
  config.omega_slack_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
}

static q15_t apply_at_rest(q15_t requested, int32_t theta_urad) {
  return pour_safety_apply(&safety, requested, theta_urad, 0);
}

void setUp(void) {
  config = pour_safety_default_config();
  init_without_band();
}

void tearDown(void) {}

static void test_safety_init_StartsAtZeroTorque(void) {
  TEST_ASSERT_EQUAL_INT16(0, safety.torque);
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
}

static void test_safety_init_RefusesBadConfigs(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(NULL, &config));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, NULL));
  config.tau_limit = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.slew_per_tick = -1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.theta_max_urad = config.theta_min_urad;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.omega_max_urad_s = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config.omega_max_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S + 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.alpha_max_urad_s2 = 999; /* below one µrad/s per tick */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.omega_slack_urad_s = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.governor_gain = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
}

static void test_safety_default_SwingsFullScaleInAbout20Ticks(void) {
  unsigned ticks = 0;
  (void)apply_at_rest(POUR_Q15_MIN, MID_URAD);
  pour_safety_force(&safety, POUR_Q15_MIN);
  while (safety.torque != POUR_Q15_MAX && ticks < 100u) {
    (void)apply_at_rest(POUR_Q15_MAX, MID_URAD);
    ++ticks;
  }
  TEST_ASSERT_EQUAL_UINT(20u, ticks);
}

static void test_safety_apply_SlewLimitsEachStep(void) {
  const q15_t t1 = apply_at_rest(POUR_Q15_MAX, MID_URAD);
  TEST_ASSERT_EQUAL_INT16(config.slew_per_tick, t1);
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_SLEW, safety.active);
  const q15_t t2 = apply_at_rest(POUR_Q15_MIN, MID_URAD);
  TEST_ASSERT_EQUAL_INT16(0, t2);
  const q15_t t3 = apply_at_rest(100, MID_URAD);
  TEST_ASSERT_EQUAL_INT16(100, t3);
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
}

static void test_safety_apply_ClampsToTauLimit(void) {
  config.tau_limit = 10000;
  config.slew_per_tick = POUR_Q15_MAX;
  init_without_band();
  TEST_ASSERT_EQUAL_INT16(10000, apply_at_rest(POUR_Q15_MAX, MID_URAD));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_CLAMP, safety.active);
  TEST_ASSERT_EQUAL_INT16(-10000, apply_at_rest(POUR_Q15_MIN, MID_URAD));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_CLAMP, safety.active);
}

static void test_safety_apply_RefusesForwardTorqueAtMaxAngle(void) {
  config.slew_per_tick = POUR_Q15_MAX;
  init_without_band();
  TEST_ASSERT_EQUAL_INT16(0, apply_at_rest(20000, config.theta_max_urad));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_ANGLE_MAX, safety.active);
  TEST_ASSERT_EQUAL_INT16(0, apply_at_rest(20000, INT32_MAX));
  /* pulling back is allowed */
  TEST_ASSERT_EQUAL_INT16(-20000, apply_at_rest(-20000, config.theta_max_urad));
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
}

static void test_safety_apply_RefusesBackwardTorqueAtMinAngle(void) {
  config.slew_per_tick = POUR_Q15_MAX;
  init_without_band();
  TEST_ASSERT_EQUAL_INT16(0, apply_at_rest(-20000, config.theta_min_urad));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_ANGLE_MIN, safety.active);
  TEST_ASSERT_EQUAL_INT16(0, apply_at_rest(-20000, INT32_MIN));
  TEST_ASSERT_EQUAL_INT16(20000, apply_at_rest(20000, config.theta_min_urad));
}

static void test_safety_apply_DropsTorqueAtLimitWithoutWaitingForSlew(void) {
  for (unsigned i = 0; i < 30u; ++i) {
    (void)apply_at_rest(POUR_Q15_MAX, MID_URAD);
  }
  TEST_ASSERT_EQUAL_INT16(POUR_Q15_MAX, safety.torque);
  /* reaching the limit: a slewed command would still push forward; it must be zero at once */
  TEST_ASSERT_EQUAL_INT16(0, apply_at_rest(POUR_Q15_MAX, config.theta_max_urad + 1));
  TEST_ASSERT_BITS_HIGH(POUR_LIMIT_ANGLE_MAX, safety.active);
}

static void test_safety_force_BypassesSlew(void) {
  for (unsigned i = 0; i < 30u; ++i) {
    (void)apply_at_rest(POUR_Q15_MAX, MID_URAD);
  }
  pour_safety_force(&safety, 0);
  TEST_ASSERT_EQUAL_INT16(0, safety.torque);
  TEST_ASSERT_EQUAL_UINT8(0u, safety.active);
  /* and the slew continues from the forced value */
  TEST_ASSERT_EQUAL_INT16(config.slew_per_tick, apply_at_rest(POUR_Q15_MAX, MID_URAD));
}


/* ---- The motion envelope (default band: ω_max 2 rad/s, α_max 3.4 rad/s², slack 0.8 rad/s, K 0.5 τ_max per
 * rad/s) ---- */

static void init_default(void) {
  config = pour_safety_default_config();
  config.slew_per_tick = POUR_Q15_MAX; /* the band alone */
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
}

static void test_safety_band_AtRestAllowsKTimesSlackEitherWay(void) {
  init_default();
  /* K · slack = 0.5 · 0.8 = 0.4 τ_max = 13107 */
  TEST_ASSERT_EQUAL_INT16(13107, pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, 0));
  TEST_ASSERT_EQUAL_HEX8(POUR_LIMIT_ACCEL, safety.active);
  pour_safety_force(&safety, 0);
  TEST_ASSERT_EQUAL_INT16(-13107, pour_safety_apply(&safety, -POUR_Q15_MAX, MID_URAD, 0));
  TEST_ASSERT_EQUAL_HEX8(POUR_LIMIT_ACCEL, safety.active);
  TEST_ASSERT_EQUAL_INT16(5000, pour_safety_apply(&safety, 5000, MID_URAD, 0)); /* inside: untouched */
  TEST_ASSERT_EQUAL_HEX8(0u, safety.active);
}

static void test_safety_band_WidensAtMostAlphaPerTick(void) {
  init_default();
  /* The bucket follows the ceiling exactly: the ceiling may rise by one alpha step (3,400 µrad/s) a tick
   * and no faster, however far the slack would let it. */
  int32_t omega = 0;
  (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, omega);
  for (unsigned t = 0; t < 100u; ++t) {
    const int32_t before = safety.ceiling_urad_s;
    omega = before;
    (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, omega);
    TEST_ASSERT_EQUAL_INT32(before + 3400, safety.ceiling_urad_s);
  }
  /* The torque that speeds it up is K · (ceiling - θ̇): one alpha step's worth. */
  TEST_ASSERT_EQUAL_INT16(56, safety.torque); /* 3.4e-3 rad/s · 16384 per rad/s = 55.7 */
  TEST_ASSERT_EQUAL_HEX8(POUR_LIMIT_ACCEL, safety.active);
}

static void test_safety_band_AboveTheSpeedLimitItBrakes(void) {
  init_default();
  for (int32_t w = 0; w <= 2000000; w += 3000) { /* ramp up along the band to the limit */
    (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, w);
  }
  TEST_ASSERT_EQUAL_INT32(config.omega_max_urad_s, safety.ceiling_urad_s);
  /* 0.2 rad/s above the limit: even a full forward request becomes a brake of K · 0.2 = 0.1 τ_max */
  TEST_ASSERT_EQUAL_INT16(-3277, pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, 2200000));
  TEST_ASSERT_EQUAL_HEX8(POUR_LIMIT_SPEED, safety.active);
  /* the same backwards */
  init_default();
  for (int32_t w = 0; w >= -2000000; w -= 3000) {
    (void)pour_safety_apply(&safety, -POUR_Q15_MAX, MID_URAD, w);
  }
  TEST_ASSERT_EQUAL_INT16(3277, pour_safety_apply(&safety, -POUR_Q15_MAX, MID_URAD, -2200000));
  TEST_ASSERT_EQUAL_HEX8(POUR_LIMIT_SPEED, safety.active);
}

static void test_safety_band_NeverLimitsBraking(void) {
  init_default();
  for (int32_t w = 0; w <= 1500000; w += 3000) {
    (void)pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, w);
  }
  /* moving forward at 1.5 rad/s: a full reverse torque slows the bucket down and passes */
  pour_safety_force(&safety, 0);
  TEST_ASSERT_EQUAL_INT16(-POUR_Q15_MAX, pour_safety_apply(&safety, -POUR_Q15_MAX, MID_URAD, 1500000));
  TEST_ASSERT_EQUAL_HEX8(0u, safety.active);
}

static void test_safety_band_SaturatesAbsurdSpeeds(void) {
  init_default();
  TEST_ASSERT_EQUAL_INT16(-POUR_Q15_MAX, pour_safety_apply(&safety, POUR_Q15_MAX, MID_URAD, INT32_MAX));
  pour_safety_force(&safety, 0);
  TEST_ASSERT_EQUAL_INT16(POUR_Q15_MAX, pour_safety_apply(&safety, POUR_Q15_MIN, MID_URAD, INT32_MIN));
}

/* ---- Closed loop: envelope + estimator on a gravity-loaded inertia, in integers ----
 * The bucket: inertia J, gravity torque -G sin θ (the liquid's centre of mass below the pivot pulls it
 * upright), Coulomb friction 0.5 N·m, τ_max 20 N·m delivered after a latency of L ticks, θ read by the
 * 17-bit encoder. 10 sub-steps of 100 µs per tick. sin by Bhaskara's formula (error < 0.2 %). */
#define TAU_MAX_MNM 20000
#define FRICTION_MNM 500
#define LATENCY_MAX 4u

typedef struct {
  int64_t theta_nrad;
  int64_t omega_urad_s;
  int32_t j_gm2;     /* inertia [g·m²] */
  int32_t g_mnm;     /* gravity torque at 90 deg [mN·m] */
  q15_t pipe[LATENCY_MAX];
  unsigned latency;  /* ticks, 1 .. LATENCY_MAX */
} bucket_t;

static int64_t sin_ppm(int64_t theta_urad) { /* sin θ · 10^6 for |θ| <= π */
  const int64_t pi = 3141593;
  const int64_t x = theta_urad < 0 ? -theta_urad : theta_urad;
  const int64_t p = x * (pi - x) / 1000;                       /* [µrad² / 1000] */
  const int64_t s = 16 * p * 1000000 / (5 * pi * pi / 1000 - 4 * p);
  return theta_urad < 0 ? -s : s;
}

static void bucket_step(bucket_t *b, q15_t command) {
  const q15_t applied = b->pipe[0];
  for (unsigned i = 0; i + 1u < b->latency; ++i) {
    b->pipe[i] = b->pipe[i + 1u];
  }
  b->pipe[b->latency - 1u] = command;
  for (int k = 0; k < 10; ++k) {
    int64_t tau = (int64_t)applied * TAU_MAX_MNM / 32768 - (int64_t)b->g_mnm * sin_ppm(b->theta_nrad / 1000) / 1000000;
    if (b->omega_urad_s != 0) {
      tau -= b->omega_urad_s > 0 ? FRICTION_MNM : -FRICTION_MNM;
    }
    b->omega_urad_s += tau * 1000000 / b->j_gm2 / 10000; /* α [µrad/s²] · 100 µs */
    b->theta_nrad += b->omega_urad_s / 10;               /* ω [µrad/s] · 100 µs [nrad] */
  }
}

static uint32_t encoder_count(int64_t theta_nrad) {
  const int64_t turn = (int64_t)1 << 17;
  int64_t c = (theta_nrad * turn + 3141592654LL) / 6283185307LL; /* round to the nearest count */
  return (uint32_t)(((c % turn) + turn) % turn);
}

typedef struct {
  int32_t peak_urad_s;     /* max |θ̇| of the bucket */
  int32_t over_ramp_urad_s; /* max of |θ̇(t)| - (slack + α_max t) over the run: > 0 = faster than the ramp */
  int32_t knee_urad_s;      /* θ̇ when θ first reaches the knee (fill schedule; 0 if it never does) */
  int32_t past_peak_urad_s; /* max |θ̇| from 0.1 rad past the knee on */
  int32_t theta_end_urad;   /* θ at the end */
  int64_t last_s_urad;      /* θ travelled in the last second */
} run_t;

static const pour_safety_config_t *loop_config; /* the closed loop's envelope, NULL: the defaults */

static bool band_off; /* the same runs without the motion envelope: the tests must fail then */

/* Requests `requested` for `ticks` from rest at theta0, with the estimator closing the loop. */
static run_t closed_loop(int32_t j_gm2, int32_t g_mnm, unsigned latency, int32_t theta0_urad, q15_t requested,
                         unsigned ticks) {
  config = loop_config != NULL ? *loop_config : pour_safety_default_config();
  if (band_off) {
    config.omega_max_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
    config.omega_slack_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
  }
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
  const pour_sensors_config_t sc = pour_sensors_default_config();
  static pour_estimator_t est;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_estimator_init(&est, &sc));
  bucket_t b = {(int64_t)theta0_urad * 1000, 0, j_gm2, g_mnm, {0}, latency};
  run_t r = {0, INT32_MIN, 0, 0, 0, 0};
  int64_t theta_1s_before_end_nrad = 0;
  for (uint32_t t = 0; t < ticks; ++t) {
    if (t + 1000u == ticks) {
      theta_1s_before_end_nrad = b.theta_nrad;
    }
    const pour_sensors_t sample = {t, encoder_count(b.theta_nrad), 10000, 0};
    pour_state_t st;
    const bool ok = pour_estimator_update(&est, &sample, &st);
    if (band_off && !ok) {
      break; /* the free bucket has spun past half a turn: the count wrapped, which the estimator refuses */
    }
    TEST_ASSERT_TRUE(ok);
    bucket_step(&b, pour_safety_apply(&safety, requested, st.theta_urad, st.omega_urad_s));
    const int32_t w = (int32_t)(b.omega_urad_s < 0 ? -b.omega_urad_s : b.omega_urad_s);
    r.peak_urad_s = w > r.peak_urad_s ? w : r.peak_urad_s;
    const int32_t ramp = config.omega_slack_urad_s + (int32_t)((int64_t)config.alpha_max_urad_s2 * t / 1000);
    r.over_ramp_urad_s = w - ramp > r.over_ramp_urad_s ? w - ramp : r.over_ramp_urad_s;
    const int64_t theta_urad = b.theta_nrad / 1000;
    if (config.knee_theta_urad != 0 && r.knee_urad_s == 0 && theta_urad >= config.knee_theta_urad) {
      r.knee_urad_s = w;
    }
    if (config.knee_theta_urad != 0 && theta_urad >= config.knee_theta_urad + 100000 && w > r.past_peak_urad_s) {
      r.past_peak_urad_s = w;
    }
  }
  r.theta_end_urad = (int32_t)(b.theta_nrad / 1000);
  r.last_s_urad = (b.theta_nrad - theta_1s_before_end_nrad) / 1000;
  return r;
}

/* Full forward torque for 1 s from upright, without gravity and with the full bucket's 5.4 N·m against the
 * motion, from the lightest inertia to twice the full bucket's, latency 1 and 2 ticks: |θ̇| stays below
 * ω_max + 0.05 rad/s, and never runs ahead of the ramp slack + α_max t by more than 0.15 rad/s (the
 * lightest bucket with 2 ticks of latency: 0.14). Without gravity the bucket does reach the limit. */
static void test_safety_closed_loop_FullForwardRequestStaysWithinTheSpeedLimit(void) {
  const int32_t inertias[] = {40, 60, 150, 300};
  for (unsigned i = 0; i < 4u; ++i) {
    for (unsigned lat = 1u; lat <= 2u; ++lat) {
      for (int32_t g = 0; g <= 5400; g += 5400) {
        const run_t r = closed_loop(inertias[i], g, lat, 0, POUR_Q15_MAX, 1000u);
        TEST_ASSERT_LESS_OR_EQUAL_INT32(config.omega_max_urad_s + 50000, r.peak_urad_s);
        TEST_ASSERT_GREATER_THAN_INT32(g == 0 ? 1950000 : 1500000, r.peak_urad_s);
        TEST_ASSERT_LESS_OR_EQUAL_INT32(150000, r.over_ramp_urad_s);
      }
    }
  }
}

/* Full reverse torque from 115 deg back toward upright, gravity pulling the same way: the governor brakes
 * against gravity; a proportional governor droops by G/(K τ_max) = 5.4 / (0.5 · 20) = 0.54 rad/s at
 * most, so |θ̇| <= ω_max + 0.54 rad/s (+ 0.05 for the estimate's lag). Without the band the same swing,
 * and the forward start, pass 10 rad/s. */
static void test_safety_closed_loop_FullReverseRequestWithGravityStaysWithinTheDroop(void) {
  const int32_t inertias[] = {40, 60, 150, 300};
  for (unsigned i = 0; i < 4u; ++i) {
    for (unsigned lat = 1u; lat <= 2u; ++lat) {
      const run_t r = closed_loop(inertias[i], 5400, lat, 2000000, POUR_Q15_MIN, 900u);
      TEST_ASSERT_LESS_OR_EQUAL_INT32(config.omega_max_urad_s + 540000 + 50000, r.peak_urad_s);
      TEST_ASSERT_GREATER_THAN_INT32(1500000, r.peak_urad_s);
    }
  }
  band_off = true;
  const run_t free_swing = closed_loop(150, 5400, 1u, 2000000, POUR_Q15_MIN, 900u);
  const run_t free_start = closed_loop(150, 5400, 1u, 0, POUR_Q15_MAX, 1000u);
  band_off = false;
  TEST_ASSERT_GREATER_THAN_INT32(10000000, free_swing.peak_urad_s);
  TEST_ASSERT_GREATER_THAN_INT32(10000000, free_start.peak_urad_s);
}


/* The fill schedule's speed limit at θ, read from the band with a slack wide enough never to bind. */
static int32_t scheduled_ceiling(int32_t theta_urad) {
  (void)pour_safety_apply(&safety, 0, theta_urad, 0);
  return safety.ceiling_urad_s;
}

static void init_schedule(int32_t knee_urad) {
  config = pour_safety_default_config();
  config.omega_slack_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S;
  config.alpha_max_urad_s2 = 1000000000;
  config.slew_per_tick = POUR_Q15_MAX;
  config.knee_theta_urad = knee_urad;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
}

static void test_safety_schedule_RefusesBadConfigs(void) {
  const int32_t knees[] = {-1, POUR_SAFETY_KNEE_MAX_URAD + 1};
  for (unsigned i = 0; i < 2u; ++i) {
    config = pour_safety_default_config();
    config.knee_theta_urad = knees[i];
    TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  }
  config = pour_safety_default_config();
  config.slow_omega_urad_s = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config.slow_omega_urad_s = POUR_SAFETY_OMEGA_MAX_URAD_S + 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.knee_decel_urad_s2 = 999;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config.knee_decel_urad_s2 = POUR_SAFETY_DECEL_MAX_URAD_S2 + 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
  config = pour_safety_default_config();
  config.slow_torque_ff = -1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_safety_init(&safety, &config));
}

/* Before the knee the ceiling is floor(sqrt(slow² + 2 · decel · (knee - θ))) up to omega_max, from the
 * knee on it is slow; with no knee it is omega_max at every tilt. */
static void test_safety_schedule_CeilingFollowsTheBrakingCurveToTheKnee(void) {
  const int32_t knee = 600000;
  init_schedule(knee);
  const int32_t thetas[] = {-3141593, 0, 300000, 500000, 590000, 599999, 600000, 700000, 2356194};
  for (unsigned i = 0; i < sizeof thetas / sizeof thetas[0]; ++i) {
    const int32_t c = scheduled_ceiling(thetas[i]);
    if (thetas[i] >= knee) {
      TEST_ASSERT_EQUAL_INT32(config.slow_omega_urad_s, c);
      continue;
    }
    const int64_t sq = (int64_t)config.slow_omega_urad_s * config.slow_omega_urad_s +
                       2 * (int64_t)config.knee_decel_urad_s2 * (knee - thetas[i]);
    if (sq >= (int64_t)config.omega_max_urad_s * config.omega_max_urad_s) {
      TEST_ASSERT_EQUAL_INT32(config.omega_max_urad_s, c);
    } else {
      TEST_ASSERT_TRUE((int64_t)c * c <= sq && ((int64_t)c + 1) * ((int64_t)c + 1) > sq);
    }
  }
  init_schedule(0);
  for (unsigned i = 0; i < sizeof thetas / sizeof thetas[0]; ++i) {
    TEST_ASSERT_EQUAL_INT32(config.omega_max_urad_s, scheduled_ceiling(thetas[i]));
  }
}

/* Past the knee, at rest under a full request, the bound is K · slow + ff + I, and I grows by K · slow ·
 * ki / 1000 a tick up to tau_limit / 2; a request below the bound does not wind it up, and back where the
 * schedule's limit is omega_max again it is gone. */
static void test_safety_schedule_IntegralLiftsTheBoundWithoutWindup(void) {
  init_schedule(600000);
  const int32_t k_slow = (int32_t)(((int64_t)config.slow_omega_urad_s * safety.gain_q32 + ((int64_t)1 << 31)) >> 32);
  TEST_ASSERT_EQUAL_INT16(k_slow + config.slow_torque_ff, pour_safety_apply(&safety, POUR_Q15_MAX, 700000, 0));
  for (int32_t n = 1; n <= 3000; ++n) {
    const int32_t integral = (int32_t)((int64_t)k_slow * config.slow_ki_per_s * n < (int64_t)config.tau_limit * 500
                                           ? (int64_t)k_slow * config.slow_ki_per_s * n
                                           : (int64_t)config.tau_limit * 500);
    TEST_ASSERT_EQUAL_INT16(k_slow + config.slow_torque_ff + integral / 1000,
                            pour_safety_apply(&safety, POUR_Q15_MAX, 700000, 0));
  }
  TEST_ASSERT_EQUAL_INT32(config.tau_limit * 500, safety.integral_mq15);
  (void)pour_safety_apply(&safety, 0, 590000, 0); /* still on the braking curve: I stays */
  TEST_ASSERT_EQUAL_INT32(config.tau_limit * 500, safety.integral_mq15);
  (void)pour_safety_apply(&safety, 0, 0, 0);
  TEST_ASSERT_EQUAL_INT32(0, safety.integral_mq15);
  for (int n = 0; n < 1000; ++n) {
    TEST_ASSERT_EQUAL_INT16(100, pour_safety_apply(&safety, 100, 700000, 0)); /* below the bound */
  }
  TEST_ASSERT_EQUAL_INT32(0, safety.integral_mq15);
}

/* However large the feed-forward and the integral, the bound never speeds the bucket up beyond omega_max. */
static void test_safety_schedule_NeverPushesBeyondTheSpeedLimit(void) {
  init_schedule(600000);
  config.slow_torque_ff = POUR_Q15_MAX;
  config.slow_omega_urad_s = config.omega_max_urad_s;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
  TEST_ASSERT_EQUAL_INT16(POUR_Q15_MAX, pour_safety_apply(&safety, POUR_Q15_MAX, 700000, 0));
  TEST_ASSERT_EQUAL_INT16(0, pour_safety_apply(&safety, POUR_Q15_MAX, 700000, config.omega_max_urad_s));
  TEST_ASSERT_LESS_THAN_INT16(0, pour_safety_apply(&safety, POUR_Q15_MAX, 700000, config.omega_max_urad_s + 100000));
}

/* Closed loop on the gravity-loaded bucket (a full bucket's 5.4 N·m at 90 deg, the knee at 34 deg where it
 * pulls 3.0 N·m back, plus 0.5 N·m of friction), full forward request from upright for 4 s: the braking
 * curve brings the bucket to the knee below slow + 0.2 rad/s (0.07 rad/s light, 0.31 at twice the full
 * bucket's inertia; unscheduled it peaks at 1.7 rad/s), past it |θ̇| stays below slow + 0.03 rad/s, and the
 * last second moves 0.16 ± 0.03 rad (0.151). The ceiling alone bounds the torque by K · slow = 1.6 N·m
 * and stalls the bucket short of the knee: without ff and integral it ends before knee + 0.05 rad. */
static void test_safety_schedule_ClosedLoopPoursAtTheSlowSpeedPastTheKnee(void) {
  const int32_t knee = 600000;
  const int32_t inertias[] = {150, 300};
  pour_safety_config_t c = pour_safety_default_config();
  c.knee_theta_urad = knee;
  loop_config = &c;
  for (unsigned i = 0; i < 2u; ++i) {
    for (unsigned lat = 1u; lat <= 2u; ++lat) {
      const run_t r = closed_loop(inertias[i], 5400, lat, 0, POUR_Q15_MAX, 4000u);
      TEST_ASSERT_LESS_OR_EQUAL_INT32(c.slow_omega_urad_s + 200000, r.knee_urad_s);
      TEST_ASSERT_LESS_OR_EQUAL_INT32(c.slow_omega_urad_s + 30000, r.past_peak_urad_s);
      TEST_ASSERT_INT32_WITHIN(30000, c.slow_omega_urad_s, (int32_t)r.last_s_urad); /* < 2^31: within 4 s */
    }
  }
  c.slow_torque_ff = 0;
  c.slow_ki_per_s = 0;
  const run_t stalled = closed_loop(150, 5400, 1u, 0, POUR_Q15_MAX, 4000u);
  c = pour_safety_default_config();
  const run_t unscheduled = closed_loop(150, 5400, 1u, 0, POUR_Q15_MAX, 4000u);
  loop_config = NULL;
  TEST_ASSERT_LESS_THAN_INT32(knee + 50000, stalled.theta_end_urad);
  TEST_ASSERT_GREATER_THAN_INT32(1500000, unscheduled.peak_urad_s);
}

/* A restart (a Reset's) leaves the envelope's run state as init does, whatever a run left in it. */
static void test_safety_restart_IsInitsRunState(void) {
  config = pour_safety_default_config();
  pour_safety_t fresh;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&fresh, &config));
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_safety_init(&safety, &config));
  for (int i = 0; i < 200; ++i) {
    (void)pour_safety_apply(&safety, 30000, MID_URAD, 3000000); /* pushing hard while moving fast */
  }
  TEST_ASSERT_NOT_EQUAL(0, safety.torque);
  pour_safety_restart(&safety);
  TEST_ASSERT_EQUAL_INT16(fresh.torque, safety.torque);
  TEST_ASSERT_EQUAL_UINT8(fresh.active, safety.active);
  TEST_ASSERT_EQUAL_INT32(fresh.alpha_step_urad_s, safety.alpha_step_urad_s);
  TEST_ASSERT_EQUAL_INT32(fresh.gain_q32, safety.gain_q32);
  TEST_ASSERT_EQUAL_INT32(fresh.ceiling_urad_s, safety.ceiling_urad_s);
  TEST_ASSERT_EQUAL_INT32(fresh.floor_urad_s, safety.floor_urad_s);
  TEST_ASSERT_EQUAL_INT32(fresh.integral_mq15, safety.integral_mq15);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_safety_init_StartsAtZeroTorque);
  RUN_TEST(test_safety_init_RefusesBadConfigs);
  RUN_TEST(test_safety_default_SwingsFullScaleInAbout20Ticks);
  RUN_TEST(test_safety_apply_SlewLimitsEachStep);
  RUN_TEST(test_safety_apply_ClampsToTauLimit);
  RUN_TEST(test_safety_apply_RefusesForwardTorqueAtMaxAngle);
  RUN_TEST(test_safety_apply_RefusesBackwardTorqueAtMinAngle);
  RUN_TEST(test_safety_apply_DropsTorqueAtLimitWithoutWaitingForSlew);
  RUN_TEST(test_safety_force_BypassesSlew);
  RUN_TEST(test_safety_band_AtRestAllowsKTimesSlackEitherWay);
  RUN_TEST(test_safety_band_WidensAtMostAlphaPerTick);
  RUN_TEST(test_safety_band_AboveTheSpeedLimitItBrakes);
  RUN_TEST(test_safety_band_NeverLimitsBraking);
  RUN_TEST(test_safety_band_SaturatesAbsurdSpeeds);
  RUN_TEST(test_safety_closed_loop_FullForwardRequestStaysWithinTheSpeedLimit);
  RUN_TEST(test_safety_closed_loop_FullReverseRequestWithGravityStaysWithinTheDroop);
  RUN_TEST(test_safety_schedule_RefusesBadConfigs);
  RUN_TEST(test_safety_schedule_CeilingFollowsTheBrakingCurveToTheKnee);
  RUN_TEST(test_safety_schedule_IntegralLiftsTheBoundWithoutWindup);
  RUN_TEST(test_safety_schedule_NeverPushesBeyondTheSpeedLimit);
  RUN_TEST(test_safety_schedule_ClosedLoopPoursAtTheSlowSpeedPastTheKnee);
  RUN_TEST(test_safety_restart_IsInitsRunState);
  return UNITY_END();
}
