/* SPDX-License-Identifier: MIT */
/* The B-G431B-ESC1's alternate-function pins, each once: X(owner, signal, port, pin, af), the signal as the
 * STM32G431's datasheet names it. tests/board/check_registers.py checks every entry against the pin maps
 * of the stm32g4xx-hal crate (generated from ST's STM32CubeMX database); docs/bringup.md says which pin
 * was checked against which board source. */
#ifndef POUR_BOARD_AF_H
#define POUR_BOARD_AF_H

/* TIM1's six gate outputs: high sides CH1..CH3, low sides CH1N..CH3N (phases U, V, W). */
#define POUR_BOARD_AF_GATES(X)                                                                                 \
  X(TIM1, CH1, A, 8, 6) X(TIM1, CH2, A, 9, 6) X(TIM1, CH3, A, 10, 6)                                           \
  X(TIM1, CH1N, C, 13, 4) X(TIM1, CH2N, A, 12, 6) X(TIM1, CH3N, B, 15, 4)
/* The motor encoder on J8 (A, B) into TIM4's encoder mode. */
#define POUR_BOARD_AF_ENCODER(X) X(TIM4, CH1, B, 6, 2) X(TIM4, CH2, B, 7, 2)
/* FDCAN1 to the board's transceiver. */
#define POUR_BOARD_AF_CAN(X) X(FDCAN1, RX, A, 11, 9) X(FDCAN1, TX, B, 9, 9)

#define POUR_BOARD_AF(X) POUR_BOARD_AF_GATES(X) POUR_BOARD_AF_ENCODER(X) POUR_BOARD_AF_CAN(X)

#endif /* POUR_BOARD_AF_H */
