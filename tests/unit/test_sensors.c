/* SPDX-License-Identifier: MIT */
/* The sensor estimator: the encoder's angle, the tracking loop's speed, the volumes from the two load cells,
 * and the samples it must refuse. */
#include <string.h>

#include "pour/sensors.h"
#include "unity.h"

static pour_sensors_config_t config;
static pour_estimator_t est;
static pour_state_t state;

#define COUNTS_17 131072u
#define TWO_PI_NRAD 6283185307LL

void setUp(void) {
  config = pour_sensors_default_config();
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_estimator_init(&est, &config));
  memset(&state, 0, sizeof state);
}

void tearDown(void) {}

/* The count a 17-bit encoder reads at θ [nrad], rounded, wrapped below upright. */
static uint32_t count_at(int64_t theta_nrad) {
  const int64_t half = theta_nrad >= 0 ? TWO_PI_NRAD / 2 : -TWO_PI_NRAD / 2;
  const int64_t c = (theta_nrad * (int64_t)COUNTS_17 + half) / TWO_PI_NRAD;
  return (uint32_t)(((c % (int64_t)COUNTS_17) + (int64_t)COUNTS_17) % (int64_t)COUNTS_17);
}

static bool feed(uint32_t seq, uint32_t encoder, int32_t m_rot, int32_t m_tgt) {
  const pour_sensors_t s = {seq, encoder, m_rot, m_tgt};
  return pour_estimator_update(&est, &s, &state);
}

static void test_sensors_init_RefusesBadConfigs(void) {
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(NULL, &config));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, NULL));
  const pour_sensors_config_t good = config;
  config.encoder_bits = POUR_ENCODER_BITS_MIN - 1u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config.encoder_bits = POUR_ENCODER_BITS_MAX + 1u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config = good;
  config.bandwidth_rad_s = 0u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config.bandwidth_rad_s = 1001u; /* ωn T > 1: the loop's poles leave the unit circle's positive half */
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config = good;
  config.scale_max_g = POUR_SCALE_LIMIT_G + 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config = good;
  config.scale_min_g = -POUR_SCALE_LIMIT_G - 1;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config = good;
  config.scale_min_g = config.scale_max_g;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config = good;
  config.mass_min_g = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config = good;
  config.jump_max_urad = 0;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
  config.jump_max_urad = 1000001;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_estimator_init(&est, &config));
}

static void test_sensors_theta_RoundsAndUnwrapsBelowUpright(void) {
  TEST_ASSERT_EQUAL_INT32(0, pour_sensors_theta_urad(0u, 17u));
  TEST_ASSERT_EQUAL_INT32(48, pour_sensors_theta_urad(1u, 17u));         /* 47.94 µrad a count */
  TEST_ASSERT_EQUAL_INT32(-48, pour_sensors_theta_urad(COUNTS_17 - 1u, 17u));
  TEST_ASSERT_EQUAL_INT32(1570796, pour_sensors_theta_urad(COUNTS_17 / 4u, 17u));
  TEST_ASSERT_EQUAL_INT32(3141593, pour_sensors_theta_urad(COUNTS_17 / 2u, 17u)); /* half a turn: +π */
  TEST_ASSERT_EQUAL_INT32(-3141545, pour_sensors_theta_urad(COUNTS_17 / 2u + 1u, 17u));
  TEST_ASSERT_EQUAL_INT32(3141593, pour_sensors_theta_urad(1u << 23, 24u));
  TEST_ASSERT_EQUAL_INT32(24544, pour_sensors_theta_urad(1u, 8u));
  for (uint32_t c = 1u; c < COUNTS_17 / 2u; c += 997u) {
    TEST_ASSERT_EQUAL_INT32(-pour_sensors_theta_urad(c, 17u), pour_sensors_theta_urad(COUNTS_17 - c, 17u));
  }
}

static void test_sensors_update_VolumesFromTheScalesAndTheFirstSample(void) {
  TEST_ASSERT_TRUE(feed(1u, 0u, 8000, 2000)); /* m0 = 10 kg */
  TEST_ASSERT_EQUAL_INT16(26214, state.v_rotating); /* 0.8 */
  TEST_ASSERT_EQUAL_INT16(6554, state.v_target);
  TEST_ASSERT_EQUAL_INT16(0, state.v_spill);
  TEST_ASSERT_EQUAL_INT32(0, state.omega_urad_s); /* a run starts at rest */
  TEST_ASSERT_TRUE(feed(2u, 0u, 5000, 4000));      /* 1 kg unaccounted: spilled or in flight */
  TEST_ASSERT_EQUAL_INT16(16384, state.v_rotating);
  TEST_ASSERT_EQUAL_INT16(13107, state.v_target);
  TEST_ASSERT_EQUAL_INT16(3277, state.v_spill);
  TEST_ASSERT_TRUE(feed(3u, 0u, -50, 10200));      /* noise below zero and an impact above m0: clipped */
  TEST_ASSERT_EQUAL_INT16(0, state.v_rotating);
  TEST_ASSERT_EQUAL_INT16(32767, state.v_target);
  TEST_ASSERT_EQUAL_INT16(1, state.v_spill); /* 1 - V: Q15 holds 1.0 only to within its last bit */
  TEST_ASSERT_TRUE(feed(4u, 0u, 2000, 9000));      /* both cells together read more than the liquid */
  TEST_ASSERT_EQUAL_INT16(0, state.v_spill);
  pour_estimator_reset(&est); /* a new run: m0 taken again */
  TEST_ASSERT_TRUE(feed(5u, 0u, 3000, 0));
  TEST_ASSERT_EQUAL_INT16(32767, state.v_rotating);
  TEST_ASSERT_EQUAL_INT32(5, (int32_t)state.seq);
}

static void test_sensors_update_RefusesImplausibleSamplesAndChangesNothing(void) {
  TEST_ASSERT_FALSE(feed(1u, 0u, 500, 400)); /* m0 = 0.9 kg < mass_min: nothing to divide by */
  TEST_ASSERT_FALSE(est.started);
  TEST_ASSERT_TRUE(feed(2u, 1000u, 9000, 1000));
  const pour_state_t good = state;
  const pour_estimator_t before = est;
  TEST_ASSERT_FALSE(feed(3u, COUNTS_17, 9000, 1000));                 /* count out of range */
  TEST_ASSERT_FALSE(feed(3u, UINT32_MAX, 9000, 1000));
  TEST_ASSERT_FALSE(feed(3u, 1000u, config.scale_max_g + 1, 1000));  /* a scale beyond its range */
  TEST_ASSERT_FALSE(feed(3u, 1000u, 9000, config.scale_min_g - 1));
  TEST_ASSERT_FALSE(feed(3u, 1000u, INT32_MIN, INT32_MAX));
  TEST_ASSERT_EQUAL_MEMORY(&good, &state, sizeof state);
  TEST_ASSERT_EQUAL_MEMORY(&before, &est, sizeof est);
  TEST_ASSERT_TRUE(feed(3u, 1000u, config.scale_max_g, config.scale_min_g)); /* the limits themselves pass */
}

/* A count that jumps (a sign flipped, a bit lost) lands far from where the loop predicted it: refused, the
 * loop untouched. The allowance grows with the square of the ticks since the last sample. */
static void test_sensors_update_RefusesAnEncoderJump(void) {
  for (uint32_t t = 0; t < 50u; ++t) {
    TEST_ASSERT_TRUE(feed(t, count_at(200000000LL + (int64_t)t * 500000), 9000, 1000)); /* 0.5 rad/s at 0.2 rad */
  }
  const pour_estimator_t before = est;
  TEST_ASSERT_FALSE(feed(50u, count_at(-200000000LL), 9000, 1000)); /* the sign flipped */
  TEST_ASSERT_FALSE(feed(50u, count_at(200000000LL + 25000000LL + 10500000LL), 9000, 1000)); /* 10.5 mrad off */
  TEST_ASSERT_EQUAL_MEMORY(&before, &est, sizeof est);
  TEST_ASSERT_TRUE(feed(50u, count_at(200000000LL + 25000000LL + 9000000LL), 9000, 1000)); /* 9 mrad: passes */
  /* two ticks later 4 · 10 mrad are allowed */
  TEST_ASSERT_TRUE(feed(52u, count_at(200000000LL + 26000000LL + 30000000LL), 9000, 1000));
}

/* Turning at 1 rad/s, the speed settles within 3 % in 20 ms; then its noise from the 17-bit counts stays
 * below 25 mrad/s (docs/safety.md: 10 mrad/s rms measured). */
static void test_sensors_update_TracksAConstantSpeed(void) {
  int32_t worst = 0;
  for (uint32_t t = 0; t < 500u; ++t) {
    TEST_ASSERT_TRUE(feed(t, count_at(100000000LL + (int64_t)t * 1000000), 9000, 1000));
    const int32_t err = state.omega_urad_s - (t == 0u ? 0 : 1000000);
    if (t >= 20u) {
      worst = err < 0 ? (-err > worst ? -err : worst) : (err > worst ? err : worst);
    }
  }
  TEST_ASSERT_LESS_OR_EQUAL_INT32(25000, worst);
  TEST_ASSERT_GREATER_THAN_INT32(0, worst); /* the quantisation is there to be filtered */
}

/* Speeding up at 50 rad/s², the speed reported is the loop's advance: it does not lag (ω̂ alone would
 * trail by 2a/ωn = 0.33 rad/s). */
static void test_sensors_update_DoesNotLagAConstantAcceleration(void) {
  for (uint32_t t = 0; t < 300u; ++t) {
    const int64_t tt = t;
    TEST_ASSERT_TRUE(feed(t, count_at(25000 * tt * tt), 9000, 1000)); /* θ = a t²/2 [nrad, t in ms] */
  }
  const int32_t truth = 50 * 2995 * 100; /* a · t in the middle of the tick ahead, 299.5 ms: the advance is the
                                          * step θ̂ takes to the next tick [µrad/s] */
  TEST_ASSERT_INT32_WITHIN(40000, truth, state.omega_urad_s);
  /* the loop's integrator ω̂, the alternative output, trails by about 2a/ωn */
  TEST_ASSERT_GREATER_THAN_INT32(250000, truth - (int32_t)((est.omega_q16 * 1000) >> 16));
}

/* Samples lost (the seq skips): the loop coasts over the gap and the speed stays right. */
static void test_sensors_update_CoastsOverLostSamples(void) {
  for (uint32_t t = 0; t < 400u; ++t) {
    if (t % 10u == 3u || t % 37u == 5u) {
      continue;
    }
    TEST_ASSERT_TRUE(feed(t, count_at((int64_t)t * 1500000), 9000, 1000)); /* 1.5 rad/s */
  }
  TEST_ASSERT_INT32_WITHIN(30000, 1500000, state.omega_urad_s);
}

/* Swinging through upright (the count wraps from 0 to 2^17 - 1): no jump in θ or θ̇. */
static void test_sensors_update_SwingsThroughUprightWithoutAJump(void) {
  for (uint32_t t = 0; t < 200u; ++t) {
    TEST_ASSERT_TRUE(feed(t, count_at(50000000LL - (int64_t)t * 500000), 9000, 1000)); /* -0.5 rad/s */
    if (t >= 20u) {
      TEST_ASSERT_INT32_WITHIN(25000, -500000, state.omega_urad_s);
    }
  }
  TEST_ASSERT_INT32_WITHIN(50, -49500, state.theta_urad);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_sensors_init_RefusesBadConfigs);
  RUN_TEST(test_sensors_theta_RoundsAndUnwrapsBelowUpright);
  RUN_TEST(test_sensors_update_VolumesFromTheScalesAndTheFirstSample);
  RUN_TEST(test_sensors_update_RefusesImplausibleSamplesAndChangesNothing);
  RUN_TEST(test_sensors_update_RefusesAnEncoderJump);
  RUN_TEST(test_sensors_update_TracksAConstantSpeed);
  RUN_TEST(test_sensors_update_DoesNotLagAConstantAcceleration);
  RUN_TEST(test_sensors_update_CoastsOverLostSamples);
  RUN_TEST(test_sensors_update_SwingsThroughUprightWithoutAJump);
  return UNITY_END();
}
