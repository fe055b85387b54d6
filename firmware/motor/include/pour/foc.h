/* SPDX-License-Identifier: MIT */
/* Field-oriented control's arithmetic: sin/cos of the electrical angle, Clarke, Park, inverse Park, and
 * min–max injection modulation to three duties. Pure integer maths: the same bits on the host and on the
 * Cortex-M4. Angles are uint16_t electrical angles (65536 = 2π, wraps); currents and voltages are per-unit
 * Q15 of the bases in pour/drive.h. */
#ifndef POUR_FOC_H
#define POUR_FOC_H

#include <stdint.h>

#include "pour/fixed.h"

/* Duty 1.0 in Q15 (duties are in [0, POUR_FOC_DUTY_ONE]). */
#define POUR_FOC_DUTY_ONE 32768

/* sin and cos of an electrical angle, Q15: a 257-entry quarter-wave table (src/sin_table.h, generated)
 * interpolated linearly, rounded to nearest: |error| <= 1 LSB; +1.0 saturates to 32767. */
void pour_foc_sincos_q15(uint16_t angle, q15_t *s, q15_t *c);

/* Amplitude-invariant Clarke transform of three phase currents (all three shunts, Q15):
 * α = (2a − b − c)/3, β = (b − c)/√3. Accumulates in int32, rounds to nearest, saturates to Q15. */
void pour_foc_clarke_q15(q15_t a, q15_t b, q15_t c, q15_t *alpha, q15_t *beta);

/* Park: d = α·cos + β·sin, q = −α·sin + β·cos (Q15 × Q15 → Q30, rounded, saturated to Q15). */
void pour_foc_park_q15(q15_t alpha, q15_t beta, q15_t s, q15_t c, q15_t *d, q15_t *q);

/* Inverse Park: α = d·cos − q·sin, β = d·sin + q·cos (as pour_foc_park_q15). */
void pour_foc_inv_park_q15(q15_t d, q15_t q, q15_t s, q15_t c, q15_t *alpha, q15_t *beta);

/* Modulation settings: the dead-time compensation and the duty ceiling. */
typedef struct {
  int32_t deadtime_duty_q15;  /* dead time / PWM period, Q15 duty: added with the sign of each phase current */
  int32_t deadtime_band_q15;  /* |i| below which the compensation is ramped linearly (current noise), Q15 current, > 0 */
  int32_t duty_max_q15;       /* highest duty (the low-side shunts need time on), Q15, <= POUR_FOC_DUTY_ONE */
} pour_foc_modulation_t;

/* Min–max injection (equivalent to space-vector modulation): the phase voltages of (α, β), shifted by
 * −(max + min)/2, over the bus voltage vbus (Q15 per-unit, > 0), centred on duty 0.5, plus the dead-time
 * compensation sign(i)·deadtime_duty for each phase current i[3] (Q15), each clamped to
 * [0, duty_max]: never out of range, whatever the inputs. duty[3] in Q15. */
void pour_foc_modulate_q15(q15_t alpha, q15_t beta, q15_t vbus, const q15_t i[3],
                           const pour_foc_modulation_t *m, int32_t duty[3]);

/* floor(√x) for a 32-bit x (Newton's iteration from above, at most 6 divisions). */
uint32_t pour_foc_isqrt_u32(uint32_t x);

#endif /* POUR_FOC_H */
