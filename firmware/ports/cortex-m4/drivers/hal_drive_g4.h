/* SPDX-License-Identifier: MIT */
/* hal_drive on the STM32G4's drivers: the period's sample from ADC1/ADC2 (adc_inj) and TIM4 (encoder_tim4),
 * the compares, the gates, the shorted phases and the break through TIM1 (pwm_tim1). The board
 * (board_stm32g431.c) brings the peripherals up and attaches them here; a host test attaches register files
 * in plain memory, so that the current loop's interrupt (board_drive) runs on the same code as on the chip. */
#ifndef POUR_HAL_DRIVE_G4_H
#define POUR_HAL_DRIVE_G4_H

#include <stdint.h>

#include "adc_inj.h"
#include "ocp.h"
#include "pwm_tim1.h"

/* The drivers' instances behind hal_drive (copied; their registers stay where they are); tim4: the encoder
 * timer's registers; ocp: the comparators (kept by pointer: armed later, pour_hal_drive_arm_overcurrent),
 * read before a break is cleared, or NULL for none. Until attached, hal_drive has no sample and every
 * output call does nothing. */
void pour_hal_drive_attach(const pour_pwm_t *pwm, const pour_adc_t *adc, volatile uint32_t *tim4,
                           const pour_ocp_t *ocp);

#endif /* POUR_HAL_DRIVE_G4_H */
