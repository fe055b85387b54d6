/* SPDX-License-Identifier: MIT */
/* Compiles the weights.h named by POUR_WEIGHTS_HEADER (a quoted path) into pour_weights_compiled.
 * A header that does not follow docs/weights-h.md fails the build with a message naming the field. */
#include "pour/weights_compiled.h"

#ifndef POUR_WEIGHTS_HEADER
#error "POUR_WEIGHTS_HEADER is not defined: set the CMake variable POUR_WEIGHTS to a weights.h"
#endif
#include POUR_WEIGHTS_HEADER

/* Before C11, glibc's and newlib's <sys/cdefs.h> turn _Static_assert into a bit-field trick that loses
 * the message; GCC and Clang accept the keyword itself in C99 mode, message included. */
#undef _Static_assert

#ifndef POUR_WEIGHTS_FORMAT
#error "weights.h: missing POUR_WEIGHTS_FORMAT"
#endif
#ifndef POUR_WEIGHTS_N_FEATURES
#error "weights.h: missing POUR_WEIGHTS_N_FEATURES"
#endif
#ifndef POUR_WEIGHTS_N_ACTIONS
#error "weights.h: missing POUR_WEIGHTS_N_ACTIONS"
#endif
#ifndef POUR_WEIGHTS_W_FRAC_BITS
#error "weights.h: missing POUR_WEIGHTS_W_FRAC_BITS"
#endif
#ifndef POUR_WEIGHTS_DECISION_PERIOD_MS
#error "weights.h: missing POUR_WEIGHTS_DECISION_PERIOD_MS"
#endif
#ifndef POUR_WEIGHTS_THETA_MIN_URAD
#error "weights.h: missing POUR_WEIGHTS_THETA_MIN_URAD"
#endif
#ifndef POUR_WEIGHTS_THETA_MAX_URAD
#error "weights.h: missing POUR_WEIGHTS_THETA_MAX_URAD"
#endif
#ifndef POUR_WEIGHTS_OMEGA_MAX_URAD_S
#error "weights.h: missing POUR_WEIGHTS_OMEGA_MAX_URAD_S"
#endif
#ifndef POUR_WEIGHTS_TAU_MAX_MNM
#error "weights.h: missing POUR_WEIGHTS_TAU_MAX_MNM"
#endif
#ifndef POUR_WEIGHTS_CONTENT_HASH
#error "weights.h: missing POUR_WEIGHTS_CONTENT_HASH"
#endif

_Static_assert(POUR_WEIGHTS_FORMAT == POUR_WEIGHTS_FORMAT_VERSION,
               "weights.h: POUR_WEIGHTS_FORMAT is not a version this firmware reads (1)");
_Static_assert(POUR_WEIGHTS_N_FEATURES == POUR_POLICY_N_FEATURES,
               "weights.h: POUR_WEIGHTS_N_FEATURES must be 6 (five observations and a bias)");
_Static_assert(POUR_WEIGHTS_N_ACTIONS >= POUR_POLICY_MIN_ACTIONS && POUR_WEIGHTS_N_ACTIONS <= POUR_POLICY_MAX_ACTIONS,
               "weights.h: POUR_WEIGHTS_N_ACTIONS must be within 2..16");
_Static_assert(POUR_WEIGHTS_W_FRAC_BITS >= 0 && POUR_WEIGHTS_W_FRAC_BITS <= 15,
               "weights.h: POUR_WEIGHTS_W_FRAC_BITS must be within 0..15");
_Static_assert(POUR_WEIGHTS_DECISION_PERIOD_MS >= 1 && POUR_WEIGHTS_DECISION_PERIOD_MS <= 65535,
               "weights.h: POUR_WEIGHTS_DECISION_PERIOD_MS must be within 1..65535");
_Static_assert(POUR_WEIGHTS_THETA_MIN_URAD >= INT32_MIN && POUR_WEIGHTS_THETA_MIN_URAD <= INT32_MAX,
               "weights.h: POUR_WEIGHTS_THETA_MIN_URAD must fit int32");
_Static_assert(POUR_WEIGHTS_THETA_MAX_URAD <= INT32_MAX &&
                   POUR_WEIGHTS_THETA_MAX_URAD > POUR_WEIGHTS_THETA_MIN_URAD,
               "weights.h: POUR_WEIGHTS_THETA_MAX_URAD must fit int32 and exceed POUR_WEIGHTS_THETA_MIN_URAD");
_Static_assert(POUR_WEIGHTS_OMEGA_MAX_URAD_S > 0 && POUR_WEIGHTS_OMEGA_MAX_URAD_S <= INT32_MAX,
               "weights.h: POUR_WEIGHTS_OMEGA_MAX_URAD_S must be a positive int32");
_Static_assert(POUR_WEIGHTS_TAU_MAX_MNM > 0 && POUR_WEIGHTS_TAU_MAX_MNM <= INT32_MAX,
               "weights.h: POUR_WEIGHTS_TAU_MAX_MNM must be a positive int32");
/* Through unsigned long long: a negative value fails, and no comparison is always true (-Wtype-limits). */
_Static_assert((unsigned long long)(POUR_WEIGHTS_CONTENT_HASH) <= 0xFFFFFFFFull,
               "weights.h: POUR_WEIGHTS_CONTENT_HASH must fit uint32");
/* sizeof catches arrays of the wrong shape or element type, and arrays declared with an empty leading
 * dimension ([]) whose initializer is short. A short initializer of an explicitly sized array is
 * zero-filled by C; the content hash refuses it at init (POUR_ECORRUPT). */
_Static_assert(sizeof(pour_weights_w) == sizeof(int16_t) * POUR_WEIGHTS_N_FEATURES * POUR_WEIGHTS_N_ACTIONS,
               "weights.h: pour_weights_w must be int16_t[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS]");
_Static_assert(sizeof(pour_weights_w[0]) == sizeof(int16_t) * POUR_WEIGHTS_N_ACTIONS,
               "weights.h: pour_weights_w rows must hold POUR_WEIGHTS_N_ACTIONS int16_t");
_Static_assert(sizeof(pour_weights_action_levels_q15) == sizeof(q15_t) * POUR_WEIGHTS_N_ACTIONS,
               "weights.h: pour_weights_action_levels_q15 must be int16_t[POUR_WEIGHTS_N_ACTIONS]");

const pour_policy_weights_t pour_weights_compiled = {
    (uint8_t)POUR_WEIGHTS_N_ACTIONS,
    (uint8_t)POUR_WEIGHTS_W_FRAC_BITS,
    (uint16_t)POUR_WEIGHTS_DECISION_PERIOD_MS,
    &pour_weights_w[0][0],
    pour_weights_action_levels_q15,
    {(int32_t)POUR_WEIGHTS_THETA_MIN_URAD, (int32_t)POUR_WEIGHTS_THETA_MAX_URAD,
     (int32_t)POUR_WEIGHTS_OMEGA_MAX_URAD_S},
    (int32_t)POUR_WEIGHTS_TAU_MAX_MNM,
    (uint32_t)POUR_WEIGHTS_CONTENT_HASH,
};
