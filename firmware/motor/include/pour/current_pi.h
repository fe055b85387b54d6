/* SPDX-License-Identifier: MIT */
/* PI current controller for one axis (d or q), per-unit Q15 in and out, gains Q16.16. */
#ifndef POUR_CURRENT_PI_H
#define POUR_CURRENT_PI_H

#include <stdint.h>

#include "pour/fixed.h"

typedef struct {
  int32_t kp_q16;    /* proportional gain, per-unit V per per-unit A, Q16.16 */
  int32_t ki_q16;    /* integral gain per loop period (Ki·Ts), per-unit, Q16.16 */
  int32_t integ_q16; /* integrator: per-unit V in Q15, << 16 (|integ| <= the last limit << 16) */
} pour_current_pi_t;

/* Gains from the motor and the bandwidth: Kp = ωc·L, Ki = ωc·R, Ki·Ts = ωc·R/f_loop, in per-unit of the
 * current base i_base_ma and the voltage base v_base_mv. POUR_EINVAL if a gain does not fit Q16.16 or
 * rounds to 0 (an implausible motor for these bases). */
pour_status_t pour_current_pi_init(pour_current_pi_t *pi, uint32_t bandwidth_rad_s, uint32_t l_nh, uint32_t r_uohm,
                                   uint32_t loop_hz, uint32_t i_base_ma, uint32_t v_base_mv);

/* One period: error e = ref − measured (Q15, int32 so that the difference cannot overflow), output limited
 * to ±limit (Q15, >= 0). Anti-windup: the integrator is clamped to the headroom the proportional part
 * leaves, so it never winds beyond what the output can use. Rounds to nearest. */
q15_t pour_current_pi_step(pour_current_pi_t *pi, int32_t e, int32_t limit);

/* Empties the integrator (on a fault, or when the PWM is off). */
void pour_current_pi_reset(pour_current_pi_t *pi);

#endif /* POUR_CURRENT_PI_H */
