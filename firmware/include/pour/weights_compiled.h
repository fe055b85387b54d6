/* SPDX-License-Identifier: MIT */
/* The policy compiled into this image: the weights.h named by CMake's POUR_WEIGHTS. */
#ifndef POUR_WEIGHTS_COMPILED_H
#define POUR_WEIGHTS_COMPILED_H

#include "pour/policy.h"

/* Validate with pour_policy_weights_validate (pour_control_init does) before use. */
extern const pour_policy_weights_t pour_weights_compiled;

#endif /* POUR_WEIGHTS_COMPILED_H */
