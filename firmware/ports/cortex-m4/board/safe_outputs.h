/* SPDX-License-Identifier: MIT */
/* The board's outputs at their safe levels from any context, a fault exception included: brake engaged,
 * power stage off, zero torque. Images without a board (tests, the benchmark) get an empty default. */
#ifndef POUR_SAFE_OUTPUTS_H
#define POUR_SAFE_OUTPUTS_H

void pour_safe_outputs(void);
/* startup.c: every fault (safe outputs, then a stop the watchdog ends), and the NMI, a fault unless the board
 * replaces it (board_stm32g431.c: a flash ECC error). */
void Fault_Handler(void);
void NMI_Handler(void);

#endif /* POUR_SAFE_OUTPUTS_H */
