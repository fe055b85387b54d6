/* SPDX-License-Identifier: MIT */
#include "pour/current_pi.h"

#include <stddef.h>

/* (num << shift)/den rounded, as a Q16.16 gain; −1 if it does not fit or rounds to 0. */
static int32_t gain_q16(uint64_t num, unsigned shift, uint64_t den) {
  if (num >= (1ULL << (63 - shift))) return -1;
  const uint64_t g = ((num << shift) + den / 2u) / den;
  return g == 0u || g > (uint64_t)INT32_MAX ? -1 : (int32_t)g;
}

pour_status_t pour_current_pi_init(pour_current_pi_t *pi, uint32_t bandwidth_rad_s, uint32_t l_nh, uint32_t r_uohm,
                                   uint32_t loop_hz, uint32_t i_base_ma, uint32_t v_base_mv) {
  if (pi == NULL || loop_hz == 0u || v_base_mv == 0u || i_base_ma == 0u) return POUR_EINVAL;
  /* Kp·i_base/v_base·2^16 = ωc·L[nH]·i_base[mA]·2^16 / (1e9·v_base[mV]), and 1e9 = 2^9·1953125.
   * Ki·Ts·i_base/v_base·2^16 = ωc·R[µΩ]·i_base[mA]·2^16 / (1e6·v_base[mV]·f_loop), and 1e6 = 2^6·15625.
   * Each numerator is below 2^17·2^32·2^17 = 2^66 only for absurd inputs; gain_q16 refuses those. */
  const uint64_t kp_num = (uint64_t)bandwidth_rad_s * l_nh;
  const uint64_t ki_num = (uint64_t)bandwidth_rad_s * r_uohm;
  if (kp_num > UINT64_MAX / i_base_ma || ki_num > UINT64_MAX / i_base_ma) return POUR_EINVAL;
  const int32_t kp = gain_q16(kp_num * i_base_ma, 7, 1953125ULL * v_base_mv);
  const int32_t ki = gain_q16(ki_num * i_base_ma, 10, 15625ULL * v_base_mv * loop_hz);
  if (kp < 0 || ki < 0) return POUR_EINVAL;
  pi->kp_q16 = kp;
  pi->ki_q16 = ki;
  pi->integ_q16 = 0;
  return POUR_OK;
}

static int32_t clamp_i32(int32_t x, int32_t lo, int32_t hi) { return x < lo ? lo : (x > hi ? hi : x); }

q15_t pour_current_pi_step(pour_current_pi_t *pi, int32_t e, int32_t limit) {
  const int32_t lim = clamp_i32(limit, 0, POUR_Q15_MAX);
  /* kp·e: Q16 × (|e| < 2^17) needs 64 bits (one SMULL); the rest stays in int32 */
  const int32_t p = clamp_i32((int32_t)(((int64_t)pi->kp_q16 * e + (1 << 15)) >> 16), -lim, lim);
  /* the integrator may hold what the output has left after the proportional part, and within ±limit itself,
   * so that (bound << 16) fits in int32 */
  const int32_t hi = lim - p < lim ? lim - p : lim;
  const int32_t lo = -lim - p > -lim ? -lim - p : -lim;
  const int64_t integ = (int64_t)pi->integ_q16 + (int64_t)pi->ki_q16 * e;
  const int64_t hi16 = (int64_t)hi * 65536, lo16 = (int64_t)lo * 65536;
  pi->integ_q16 = (int32_t)(integ > hi16 ? hi16 : (integ < lo16 ? lo16 : integ));
  return (q15_t)clamp_i32(p + ((pi->integ_q16 + (1 << 15)) >> 16), -lim, lim);
}

void pour_current_pi_reset(pour_current_pi_t *pi) { pi->integ_q16 = 0; }
