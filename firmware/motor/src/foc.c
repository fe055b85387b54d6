/* SPDX-License-Identifier: MIT */
#include "pour/foc.h"

/* Taylor coefficients of sin(πz/2) = Σ c_k z^k on z ∈ [0, 1], Q30. The next term, (π/2)^11/11!, is
 * 3.6e-6: below half a Q15 LSB. */
#define SIN_C1 1686629713LL
#define SIN_C3 (-693598668LL)
#define SIN_C5 85569306LL
#define SIN_C7 (-5026995LL)
#define SIN_C9 172272LL
#define Q30_ONE (1LL << 30)
#define INV_SQRT3_Q15 18919 /* 1/√3 in Q15 */

static int64_t mul_q30(int64_t a, int64_t b) { return (a * b + (1LL << 29)) >> 30; }

/* sin of the quarter-wave position r ∈ [0, 16384] (Q14 of π/2), Q15, saturated. */
static q15_t sin_quarter(int32_t r) {
  const int64_t z = (int64_t)r << 16; /* Q30 */
  const int64_t z2 = mul_q30(z, z);
  int64_t p = SIN_C9;
  p = SIN_C7 + mul_q30(p, z2);
  p = SIN_C5 + mul_q30(p, z2);
  p = SIN_C3 + mul_q30(p, z2);
  p = SIN_C1 + mul_q30(p, z2);
  const int64_t s = mul_q30(p, z); /* Q30 */
  return pour_sat_q15((int32_t)((s + (1LL << 14)) >> 15));
}

static q15_t sin_angle(uint16_t angle) {
  const uint32_t quadrant = (uint32_t)angle >> 14;
  int32_t r = (int32_t)(angle & 0x3FFFu);
  if (quadrant & 1u) r = 16384 - r;
  const q15_t s = sin_quarter(r);
  return quadrant >= 2u ? (q15_t)-s : s; /* s >= 0, so −s fits */
}

void pour_foc_sincos_q15(uint16_t angle, q15_t *s, q15_t *c) {
  *s = sin_angle(angle);
  *c = sin_angle((uint16_t)(angle + 16384u));
}

static q15_t round_q30_to_q15(int64_t x) { return pour_sat_q15(pour_sat_i32((x + (1LL << 14)) >> 15)); }

void pour_foc_clarke_q15(q15_t a, q15_t b, q15_t c, q15_t *alpha, q15_t *beta) {
  /* (2a − b − c)/3, rounded to nearest (ties away from zero) */
  const int32_t num = 2 * (int32_t)a - (int32_t)b - (int32_t)c;
  *alpha = pour_sat_q15(num >= 0 ? (num + 1) / 3 : (num - 1) / 3);
  *beta = round_q30_to_q15((int64_t)((int32_t)b - (int32_t)c) * INV_SQRT3_Q15);
}

void pour_foc_park_q15(q15_t alpha, q15_t beta, q15_t s, q15_t c, q15_t *d, q15_t *q) {
  *d = round_q30_to_q15((int64_t)alpha * c + (int64_t)beta * s);
  *q = round_q30_to_q15((int64_t)beta * c - (int64_t)alpha * s);
}

void pour_foc_inv_park_q15(q15_t d, q15_t q, q15_t s, q15_t c, q15_t *alpha, q15_t *beta) {
  *alpha = round_q30_to_q15((int64_t)d * c - (int64_t)q * s);
  *beta = round_q30_to_q15((int64_t)d * s + (int64_t)q * c);
}

static int32_t clamp_i32(int32_t x, int32_t lo, int32_t hi) { return x < lo ? lo : (x > hi ? hi : x); }

void pour_foc_modulate_q15(q15_t alpha, q15_t beta, q15_t vbus, const q15_t i[3],
                           const pour_foc_modulation_t *m, int32_t duty[3]) {
  /* inverse Clarke: a = α, b = −α/2 + β·√3/2, c = −α/2 − β·√3/2 (int32: no overflow for Q15 inputs) */
  const int32_t half_sqrt3_beta = (int32_t)(((int64_t)beta * 28378 + (1 << 14)) >> 15); /* √3/2 in Q15 */
  int32_t v[3];
  v[0] = alpha;
  v[1] = -alpha / 2 + half_sqrt3_beta;
  v[2] = -alpha / 2 - half_sqrt3_beta;
  int32_t vmax = v[0], vmin = v[0];
  for (int k = 1; k < 3; ++k) {
    if (v[k] > vmax) vmax = v[k];
    if (v[k] < vmin) vmin = v[k];
  }
  const int32_t offset = -(vmax + vmin) / 2;
  const int32_t bus = vbus > 0 ? vbus : 1;
  for (int k = 0; k < 3; ++k) {
    /* (v + offset)/vbus in Q15: |v + offset| < 2^16, so the shifted numerator fits in int64 easily */
    int32_t d = (int32_t)(((int64_t)(v[k] + offset) << 15) / bus);
    d = clamp_i32(d, -POUR_FOC_DUTY_ONE, POUR_FOC_DUTY_ONE) + POUR_FOC_DUTY_ONE / 2;
    const int32_t band = m->deadtime_band_q15 > 0 ? m->deadtime_band_q15 : 1;
    const int32_t ic = clamp_i32(i[k], -band, band);
    d += (int32_t)(((int64_t)m->deadtime_duty_q15 * ic) / band);
    duty[k] = clamp_i32(d, 0, m->duty_max_q15);
  }
}

uint32_t pour_foc_isqrt_u32(uint32_t x) {
  uint32_t root = 0, bit = 1u << 30;
  while (bit > x) bit >>= 2;
  while (bit != 0u) {
    if (x >= root + bit) {
      x -= root + bit;
      root = (root >> 1) + bit;
    } else {
      root >>= 1;
    }
    bit >>= 2;
  }
  return root;
}
