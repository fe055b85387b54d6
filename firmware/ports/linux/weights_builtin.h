/* SPDX-License-Identifier: MIT */
/* The policy compiled into the controller (CMake's POUR_WEIGHTS, a weights.h file). */
#ifndef POUR_LINUX_WEIGHTS_BUILTIN_H
#define POUR_LINUX_WEIGHTS_BUILTIN_H

#include "pour/policy.h"

/* The compiled-in weights; validate them with pour_policy_weights_validate (init does). */
const pour_policy_weights_t *pour_weights_builtin(void);

/* Path of the weights.h they came from, for messages. */
const char *pour_weights_builtin_path(void);

#endif /* POUR_LINUX_WEIGHTS_BUILTIN_H */
