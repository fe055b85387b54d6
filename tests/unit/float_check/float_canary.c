/* SPDX-License-Identifier: MIT */
/* Deliberately uses float: the soft-float check must find __aeabi_* helpers in this object. */
#include <stdint.h>

int32_t pour_float_canary(int32_t a, int32_t b);

int32_t pour_float_canary(int32_t a, int32_t b) { return (int32_t)((float)a * 0.5f + (float)b); }
