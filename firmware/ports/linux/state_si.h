/* SPDX-License-Identifier: MIT */
/* Physical plant state in SI units (as host_sim computes it) to the core's fixed-point pour_state_t.
 * The in-process simulator and the LCM controller use this one conversion, so both feed the core
 * bit-identical inputs. */
#ifndef POUR_LINUX_STATE_SI_H
#define POUR_LINUX_STATE_SI_H

#include <stdint.h>

#include "pour/obs.h"

/* θ [rad] → [µrad]: θ·1e6 rounded half away from zero, saturated to int32; NaN becomes INT32_MAX. */
int32_t pour_si_to_urad(double rad);

/* Volume fraction [1] → Q15: v·32768 rounded to nearest (ties to even, as host_sim's in-process
 * controller does), saturated to [0, 32767]; NaN becomes -32768 so that the core flags BAD_INPUT. */
q15_t pour_si_to_q15(double fraction);

/* Fills *state from SI values: θ [rad], ω [rad/s], volume fractions [1]; seq is the low 32 bits. */
void pour_state_from_si(pour_state_t *state, int64_t seq, double theta, double omega, double v_rotating,
                        double v_target, double v_spill);

#endif /* POUR_LINUX_STATE_SI_H */
