/* SPDX-License-Identifier: MIT */
/* hal_can for the Cortex-M4 port: a register-level driver for the STM32G4 FDCAN peripheral in classic
 * CAN mode (1 Mbit/s, 11-bit ids), polled from the 1 kHz loop. No interrupts, no HAL.
 *
 * Message RAM (STM32G4: fixed layout, 0x350 bytes per instance; RM0440 "FDCAN message RAM"):
 *   0x000 28 standard filters x 1 word   (we use element 0: this node's ids -> RX FIFO 0)
 *   0x070  8 extended filters x 2 words  (unused: extended frames are rejected)
 *   0x0B0 RX FIFO 0, 3 elements x 18 words (overwrite mode: the newest frames win)
 *   0x188 RX FIFO 1, 3 x 18 words        (unused)
 *   0x260 TX event FIFO, 3 x 2 words     (unused)
 *   0x278 TX FIFO, 3 elements x 18 words
 * The registers and the message RAM are reached through pointers in pour_fdcan_t, so the same driver
 * runs against plain memory in the host unit test (tests/can/test_fdcan.c). */
#ifndef POUR_FDCAN_H
#define POUR_FDCAN_H

#include <stdint.h>

#include "pour/can_codec.h"
#include "pour/fixed.h"
#include "regs.h"

/* The registers and fields the driver uses (regs.h's table form; RM0440 names). */
#define POUR_FDCAN_PERIPHS(P) P(FDCAN1, FDCAN, 0x40006400) P(SRAMCAN, SRAMCAN, 0x4000A400)
#define POUR_FDCAN_REGS(R)                                                                                     \
  R(FDCAN, CCCR, 0x018)                                                                                        \
  R(FDCAN, NBTP, 0x01C)                                                                                        \
  R(FDCAN, ECR, 0x040)                                                                                         \
  R(FDCAN, PSR, 0x044)                                                                                         \
  R(FDCAN, IR, 0x050)                                                                                          \
  R(FDCAN, IE, 0x054)                                                                                          \
  R(FDCAN, RXGFC, 0x080)                                                                                       \
  R(FDCAN, RXF0S, 0x090)                                                                                       \
  R(FDCAN, RXF0A, 0x094)                                                                                       \
  R(FDCAN, TXBC, 0x0C0)                                                                                        \
  R(FDCAN, TXFQS, 0x0C4)                                                                                       \
  R(FDCAN, TXBAR, 0x0CC)
#define POUR_FDCAN_FIELDS(F)                                                                                   \
  F(FDCAN, CCCR, INIT, 0, 1)                                                                                   \
  F(FDCAN, CCCR, CCE, 1, 1)                                                                                    \
  F(FDCAN, CCCR, ASM, 2, 1)                                                                                    \
  F(FDCAN, CCCR, MON, 5, 1)                                                                                    \
  F(FDCAN, CCCR, DAR, 6, 1)                                                                                    \
  F(FDCAN, CCCR, TEST, 7, 1)                                                                                   \
  F(FDCAN, CCCR, FDOE, 8, 1)                                                                                   \
  F(FDCAN, CCCR, BRSE, 9, 1)                                                                                   \
  F(FDCAN, NBTP, NTSEG2, 0, 7)                                                                                 \
  F(FDCAN, NBTP, NTSEG1, 8, 8)                                                                                 \
  F(FDCAN, NBTP, NBRP, 16, 9)                                                                                  \
  F(FDCAN, NBTP, NSJW, 25, 7)                                                                                  \
  F(FDCAN, PSR, BO, 7, 1)                                                                                      \
  F(FDCAN, IR, RF0L, 2, 1)                                                                                     \
  F(FDCAN, RXGFC, RRFE, 0, 1)                                                                                  \
  F(FDCAN, RXGFC, RRFS, 1, 1)                                                                                  \
  F(FDCAN, RXGFC, ANFE, 2, 2)                                                                                  \
  F(FDCAN, RXGFC, ANFS, 4, 2)                                                                                  \
  F(FDCAN, RXGFC, F0OM, 9, 1)                                                                                  \
  F(FDCAN, RXGFC, LSS, 16, 5)                                                                                  \
  F(FDCAN, RXF0S, F0FL, 0, 4)                                                                                  \
  F(FDCAN, RXF0S, F0GI, 8, 2)                                                                                  \
  F(FDCAN, RXF0S, RF0L, 25, 1)                                                                                 \
  F(FDCAN, TXFQS, TFQPI, 16, 2)                                                                                \
  F(FDCAN, TXFQS, TFQF, 21, 1)
POUR_REGS_DECLARE(FDCAN);
#define POUR_FDCAN_N_REGS (0x100 / 4) /* the register file a host test provides [words] */

/* Message RAM layout [32-bit words] (see above). */
#define POUR_FDCAN_RAM_WORDS (0x350u / 4u)
#define POUR_FDCAN_RAM_FLS 0u                /* standard filter list */
#define POUR_FDCAN_RAM_RF0 (0x0B0u / 4u)     /* RX FIFO 0 */
#define POUR_FDCAN_RAM_TXQ (0x278u / 4u)     /* TX FIFO */
#define POUR_FDCAN_ELEMENT_WORDS 18u         /* RX/TX element: 2 header words + 64 data bytes */
#define POUR_FDCAN_FIFO_ELEMENTS 3u

typedef struct {
  volatile uint32_t *regs; /* instance registers (POUR_FDCAN_N_REGS words) */
  volatile uint32_t *ram;  /* the instance's message RAM (POUR_FDCAN_RAM_WORDS words) */
} pour_fdcan_hw_t;

typedef struct {
  uint32_t kernel_clock_hz; /* FDCAN kernel clock (PCLK1 here) [Hz] */
  uint32_t bitrate;         /* nominal bit rate [bit/s], 1,000,000 on the bench */
  uint8_t node_id;          /* only this node's ids pass the acceptance filter */
  uint16_t init_timeout;    /* polls of CCCR.INIT before giving up, > 0 */
} pour_fdcan_config_t;

/* Nominal bit timing, as the NBTP fields hold them (each value - 1 is written). */
typedef struct {
  uint16_t prescaler; /* 1 .. 512 */
  uint8_t tseg1;      /* time quanta before the sample point, sync excluded: 2 .. 256 */
  uint8_t tseg2;      /* time quanta after it: 2 .. 128 */
  uint8_t sjw;        /* 1 .. tseg2 */
} pour_fdcan_timing_t;

typedef struct {
  pour_fdcan_hw_t hw;
  pour_fdcan_config_t config;
  uint32_t rx_frames;
  uint32_t rx_rejected;  /* FD, extended or remote frames that reached the FIFO anyway */
  uint32_t rx_lost;      /* FIFO overruns seen (RF0L) */
  uint32_t tx_frames;
  uint32_t tx_full;      /* frames not queued: TX FIFO full */
  uint32_t bus_off;      /* bus-off events recovered from */
} pour_fdcan_t;

/* Bit timing for bitrate from clock_hz: 8 .. 25 quanta per bit, sample point nearest 87.5 %, the fewest
 * quanta-rounding errors first (exact bit rates only). POUR_EINVAL if no exact timing exists. */
pour_status_t pour_fdcan_timing(uint32_t clock_hz, uint32_t bitrate, pour_fdcan_timing_t *timing);

/* Default: 16 MHz kernel clock (STM32G431 reset clock), 1 Mbit/s, node 0. */
pour_fdcan_config_t pour_fdcan_default_config(void);

/* FDCAN1 and its message RAM on the STM32G431. */
pour_fdcan_hw_t pour_fdcan_stm32g4_fdcan1(void);

/* Configures the peripheral (classic CAN, filters, FIFOs, bit timing) and starts it on the bus.
 * POUR_EINVAL for a bad config, no exact bit timing, or a CCCR.INIT that never acknowledges. */
pour_status_t pour_fdcan_init(pour_fdcan_t *can, pour_fdcan_hw_t hw, const pour_fdcan_config_t *config);

/* Takes the oldest classic data frame from RX FIFO 0: 1 if one was read into *frame, 0 if there is none
 * (FD, extended or remote frames are skipped and counted). */
int pour_fdcan_receive(pour_fdcan_t *can, pour_can_frame_t *frame);

/* Queues a frame in the TX FIFO: 0, or -1 if the FIFO is full (the frame is dropped and counted). */
int pour_fdcan_transmit(pour_fdcan_t *can, const pour_can_frame_t *frame);

/* Once per tick: notes FIFO overruns and restarts the controller after bus-off. Returns 1 while the
 * controller is bus-off (or recovering), else 0. */
int pour_fdcan_poll(pour_fdcan_t *can);

#endif /* POUR_FDCAN_H */
