/* SPDX-License-Identifier: MIT */
/* hal_can: classic CAN frames in and out for the loop (on the STM32G431: FDCAN1, fdcan.c). */
#ifndef POUR_HAL_CAN_H
#define POUR_HAL_CAN_H

#include <stdint.h>

#include "pour/can_codec.h"

/* Brings the bus up for node_id's frames from a kernel clock of clock_hz [Hz]; POUR_OK or the driver's error. */
pour_status_t pour_hal_can_init(uint32_t clock_hz, uint8_t node_id);

/* Once per tick, before receiving: bus-off recovery and overrun accounting. */
void pour_hal_can_poll(void);

/* The oldest received frame: 1 if one was read into *frame, 0 if there is none. */
int pour_hal_can_receive(pour_can_frame_t *frame);

/* Queues a frame: 0, or -1 if it was dropped (queue full). */
int pour_hal_can_transmit(const pour_can_frame_t *frame);

#endif /* POUR_HAL_CAN_H */
