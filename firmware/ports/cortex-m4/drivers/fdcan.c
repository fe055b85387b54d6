/* SPDX-License-Identifier: MIT */
#include "fdcan.h"

#include <stddef.h>

#define CCCR_INIT POUR_MSK(FDCAN, CCCR, INIT)
#define CCCR_CCE POUR_MSK(FDCAN, CCCR, CCE)
#define IR_RF0L POUR_MSK(FDCAN, IR, RF0L)
#define RXF0S_RF0L POUR_MSK(FDCAN, RXF0S, RF0L)
#define RXGFC_REJECT 2u /* ANFS, ANFE: reject frames no filter accepts */
/* Element header words */
#define E0_XTD (1u << 30)
#define E0_RTR (1u << 29)
#define E0_STDID_POS 18u
#define E1_DLC_POS 16u
#define E1_FDF (1u << 21)
/* Standard filter element: classic filter (SFID1 = id, SFID2 = mask), store in RX FIFO 0. */
#define SF_CLASSIC (2u << 30)
#define SF_TO_FIFO0 (1u << 27)
#define SF_ID1_POS 16u

pour_status_t pour_fdcan_timing(uint32_t clock_hz, uint32_t bitrate, pour_fdcan_timing_t *timing) {
  if (timing == NULL || bitrate == 0u || clock_hz < bitrate * 8u) {
    return POUR_EINVAL;
  }
  /* Most quanta first: a finer sample-point grid. */
  for (uint32_t tq = 25u; tq >= 8u; --tq) {
    const uint64_t per_bit = (uint64_t)bitrate * tq;
    if (clock_hz % per_bit != 0u) {
      continue;
    }
    const uint64_t prescaler = clock_hz / per_bit;
    if (prescaler < 1u || prescaler > 512u) {
      continue;
    }
    uint32_t tseg2 = (tq + 4u) / 8u; /* sample point nearest 87.5 % (CiA 301) */
    if (tseg2 < 2u) {
      tseg2 = 2u;
    }
    timing->prescaler = (uint16_t)prescaler;
    timing->tseg2 = (uint8_t)tseg2;
    timing->tseg1 = (uint8_t)(tq - 1u - tseg2);
    timing->sjw = (uint8_t)tseg2;
    return POUR_OK;
  }
  return POUR_EINVAL;
}

pour_fdcan_config_t pour_fdcan_default_config(void) {
  pour_fdcan_config_t c;
  c.kernel_clock_hz = 16000000u;
  c.bitrate = 1000000u;
  c.node_id = 0;
  c.init_timeout = 10000u;
  return c;
}

pour_fdcan_hw_t pour_fdcan_stm32g4_fdcan1(void) {
  pour_fdcan_hw_t hw;
  hw.regs = (volatile uint32_t *)(uintptr_t)POUR_FDCAN1_BASE;
  hw.ram = (volatile uint32_t *)(uintptr_t)POUR_SRAMCAN_BASE;
  return hw;
}

static int wait_init(const pour_fdcan_t *can, uint32_t want) {
  for (uint32_t i = 0; i < can->config.init_timeout; ++i) {
    if ((can->hw.regs[POUR_FDCAN_CCCR] & CCCR_INIT) == want) {
      return 0;
    }
  }
  return -1;
}

pour_status_t pour_fdcan_init(pour_fdcan_t *can, pour_fdcan_hw_t hw, const pour_fdcan_config_t *config) {
  pour_fdcan_timing_t t;
  if (can == NULL || config == NULL || hw.regs == NULL || hw.ram == NULL || config->node_id > POUR_CAN_NODE_ID_MAX ||
      config->init_timeout == 0u || pour_fdcan_timing(config->kernel_clock_hz, config->bitrate, &t) != POUR_OK) {
    return POUR_EINVAL;
  }
  pour_fdcan_t zero = {{NULL, NULL}, {0u, 0u, 0u, 0u}, 0u, 0u, 0u, 0u, 0u, 0u};
  *can = zero;
  can->hw = hw;
  can->config = *config;
  volatile uint32_t *r = hw.regs;

  /* Configuration needs INIT, then CCE (RM0440: CCE is writable only while INIT is set). */
  r[POUR_FDCAN_CCCR] |= CCCR_INIT;
  if (wait_init(can, CCCR_INIT) != 0) {
    return POUR_EINVAL;
  }
  r[POUR_FDCAN_CCCR] |= CCCR_CCE;
  /* Classic CAN, automatic retransmission, normal (not monitoring, restricted or test) operation. */
  r[POUR_FDCAN_CCCR] &= ~(POUR_MSK(FDCAN, CCCR, FDOE) | POUR_MSK(FDCAN, CCCR, BRSE) | POUR_MSK(FDCAN, CCCR, DAR) |
                          POUR_MSK(FDCAN, CCCR, ASM) | POUR_MSK(FDCAN, CCCR, MON) | POUR_MSK(FDCAN, CCCR, TEST));
  r[POUR_FDCAN_NBTP] = POUR_VAL(FDCAN, NBTP, NSJW, t.sjw - 1u) | POUR_VAL(FDCAN, NBTP, NBRP, t.prescaler - 1u) |
                       POUR_VAL(FDCAN, NBTP, NTSEG1, t.tseg1 - 1u) | POUR_VAL(FDCAN, NBTP, NTSEG2, t.tseg2 - 1u);

  for (uint32_t i = 0; i < POUR_FDCAN_RAM_WORDS; ++i) {
    hw.ram[i] = 0u; /* the message RAM is not reset with the peripheral */
  }
  hw.ram[POUR_FDCAN_RAM_FLS] = SF_CLASSIC | SF_TO_FIFO0 |
                               ((uint32_t)pour_can_id(config->node_id, 0) << SF_ID1_POS) | POUR_CAN_NODE_MASK;
  /* One standard filter; everything else (other nodes, extended and remote frames) is rejected in
   * hardware. FIFO 0 overwrites: with three elements, the newest state must win. */
  r[POUR_FDCAN_RXGFC] = POUR_VAL(FDCAN, RXGFC, LSS, 1u) | POUR_MSK(FDCAN, RXGFC, F0OM) |
                        POUR_VAL(FDCAN, RXGFC, ANFS, RXGFC_REJECT) | POUR_VAL(FDCAN, RXGFC, ANFE, RXGFC_REJECT) |
                        POUR_MSK(FDCAN, RXGFC, RRFS) | POUR_MSK(FDCAN, RXGFC, RRFE);
  r[POUR_FDCAN_TXBC] = 0u;  /* TX FIFO mode (not queue) */
  r[POUR_FDCAN_IE] = 0u;    /* polled from the 1 kHz loop */
  r[POUR_FDCAN_IR] = 0xFFFFFFFFu;

  r[POUR_FDCAN_CCCR] &= ~(CCCR_INIT | CCCR_CCE);
  return wait_init(can, 0u) == 0 ? POUR_OK : POUR_EINVAL;
}

int pour_fdcan_receive(pour_fdcan_t *can, pour_can_frame_t *frame) {
  volatile uint32_t *r = can->hw.regs;
  /* Bounded: at most the FIFO's depth of rejected elements is skipped per call. */
  for (unsigned n = 0; n < POUR_FDCAN_FIFO_ELEMENTS; ++n) {
    const uint32_t status = r[POUR_FDCAN_RXF0S];
    if (POUR_GET(FDCAN, RXF0S, F0FL, status) == 0u) {
      return 0;
    }
    const uint32_t gi = POUR_GET(FDCAN, RXF0S, F0GI, status);
    const volatile uint32_t *e = &can->hw.ram[POUR_FDCAN_RAM_RF0 + gi * POUR_FDCAN_ELEMENT_WORDS];
    const uint32_t e0 = e[0];
    const uint32_t e1 = e[1];
    const uint32_t d0 = e[2];
    const uint32_t d1 = e[3];
    r[POUR_FDCAN_RXF0A] = gi; /* frees the element */
    const uint32_t dlc = (e1 >> E1_DLC_POS) & 0xFu;
    if ((e0 & (E0_XTD | E0_RTR)) != 0u || (e1 & E1_FDF) != 0u || dlc > 8u) {
      can->rx_rejected++;
      continue;
    }
    frame->id = (uint16_t)((e0 >> E0_STDID_POS) & POUR_CAN_STD_ID_MAX);
    frame->dlc = (uint8_t)dlc;
    for (unsigned i = 0; i < 4u; ++i) {
      frame->data[i] = (uint8_t)(d0 >> (8u * i));
      frame->data[4u + i] = (uint8_t)(d1 >> (8u * i));
    }
    can->rx_frames++;
    return 1;
  }
  return 0;
}

int pour_fdcan_transmit(pour_fdcan_t *can, const pour_can_frame_t *frame) {
  volatile uint32_t *r = can->hw.regs;
  const uint32_t status = r[POUR_FDCAN_TXFQS];
  if ((status & POUR_MSK(FDCAN, TXFQS, TFQF)) != 0u || frame->dlc > 8u) {
    can->tx_full++;
    return -1;
  }
  const uint32_t pi = POUR_GET(FDCAN, TXFQS, TFQPI, status);
  volatile uint32_t *e = &can->hw.ram[POUR_FDCAN_RAM_TXQ + pi * POUR_FDCAN_ELEMENT_WORDS];
  uint32_t d0 = 0u;
  uint32_t d1 = 0u;
  for (unsigned i = 0; i < 4u; ++i) {
    d0 |= (uint32_t)frame->data[i] << (8u * i);
    d1 |= (uint32_t)frame->data[4u + i] << (8u * i);
  }
  e[0] = ((uint32_t)frame->id & POUR_CAN_STD_ID_MAX) << E0_STDID_POS;
  e[1] = (uint32_t)frame->dlc << E1_DLC_POS; /* classic, no bit-rate switch, no TX event */
  e[2] = d0;
  e[3] = d1;
  r[POUR_FDCAN_TXBAR] = 1u << pi;
  can->tx_frames++;
  return 0;
}

int pour_fdcan_poll(pour_fdcan_t *can) {
  volatile uint32_t *r = can->hw.regs;
  if ((r[POUR_FDCAN_RXF0S] & RXF0S_RF0L) != 0u) {
    can->rx_lost++;
    r[POUR_FDCAN_IR] = IR_RF0L; /* write 1 to clear */
  }
  if ((r[POUR_FDCAN_PSR] & POUR_MSK(FDCAN, PSR, BO)) == 0u) {
    return 0;
  }
  /* Bus-off sets INIT; clearing it starts the recovery (128 x 11 recessive bits), then the bus again. */
  if ((r[POUR_FDCAN_CCCR] & CCCR_INIT) != 0u) {
    r[POUR_FDCAN_CCCR] &= ~CCCR_INIT;
    can->bus_off++;
  }
  return 1;
}
