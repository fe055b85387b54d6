/* SPDX-License-Identifier: MIT */
#include "pour/foc.h"

#include "sin_table.h"

#define INV_SQRT3_Q15 18919 /* 1/√3 in Q15 */

/* sin of the quarter-wave position r ∈ [0, 16384] (Q14 of π/2), Q15: the table's two neighbours
 * interpolated linearly on the 6 bits between them, rounded (error below 1 LSB). */
static q15_t sin_quarter(int32_t r) {
  const int32_t k = r >> 6, frac = r & 63;
  if (k >= POUR_SIN_TABLE_STEPS) return pour_sin_table[POUR_SIN_TABLE_STEPS];
  const int32_t a = pour_sin_table[k], b = pour_sin_table[k + 1];
  return (q15_t)(a + (((b - a) * frac + 32) >> 6));
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

/* A sum of two Q15 × Q15 products (|x| <= 2^31) rounded to Q15 and saturated: after the shift it fits int32. */
static q15_t round_q30_to_q15(int64_t x) { return pour_sat_q15((int32_t)((x + (1LL << 14)) >> 15)); }

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
  /* 1/vbus once, Q30 (a 32-bit division), then a multiply per phase */
  const int32_t inv_bus = (int32_t)((1 << 30) / (vbus > 0 ? vbus : 1));
  const int32_t band = m->deadtime_band_q15 > 0 ? m->deadtime_band_q15 : 1;
  for (int k = 0; k < 3; ++k) {
    /* (v + offset)/vbus in Q15: |v + offset| < 2^17 and inv_bus <= 2^30, so the product fits in int64 */
    int32_t d = (int32_t)(((int64_t)(v[k] + offset) * inv_bus + (1 << 14)) >> 15);
    d = clamp_i32(d, -POUR_FOC_DUTY_ONE, POUR_FOC_DUTY_ONE) + POUR_FOC_DUTY_ONE / 2;
    /* deadtime_duty·clamp(i, ±band)/band: both below 2^15, so the product fits in int32 */
    d += m->deadtime_duty_q15 * clamp_i32(i[k], -band, band) / band;
    duty[k] = clamp_i32(d, 0, m->duty_max_q15);
  }
}

uint32_t pour_foc_isqrt_u32(uint32_t x) {
  if (x < 2u) return x;
  /* Newton from above: r0 = 2^ceil(bits/2) >= √x, then r ← (r + x/r)/2 falls monotonically to floor(√x)
   * (at most 6 steps for 32 bits; one hardware division each) */
  unsigned bits = 0;
#if defined(__GNUC__)
  bits = 32u - (unsigned)__builtin_clz(x);
#else
  while (bits < 32u && (x >> bits) != 0u) ++bits;
#endif
  uint32_t r = 1u << ((bits + 1u) / 2u);
  for (;;) {
    const uint32_t next = (r + x / r) / 2u;
    if (next >= r) return r;
    r = next;
  }
}
