/* SPDX-License-Identifier: MIT */
/* The board's outputs at their safe levels from any context, a fault exception included: brake engaged,
 * power stage off, zero torque. Images without a board (tests, the benchmark) get an empty default. */
#ifndef POUR_SAFE_OUTPUTS_H
#define POUR_SAFE_OUTPUTS_H

void pour_safe_outputs(void);

#endif /* POUR_SAFE_OUTPUTS_H */
