/* SPDX-License-Identifier: MIT */
/* The STM32G431's shared blocks as the board code uses them (regs.h's table form): reset and clock control,
 * power, the flash interface's access control, the independent watchdog, the low-power timer that times the
 * crystal against HSI16 at boot (clock.c), and the GPIO ports. */
#ifndef POUR_STM32G431_REGS_H
#define POUR_STM32G431_REGS_H

#include "regs.h"

#define POUR_CHIP_PERIPHS(P)                                                                                   \
  P(RCC, RCC, 0x40021000)                                                                                      \
  P(PWR, PWR, 0x40007000)                                                                                      \
  P(FLASH, FLASH, 0x40022000)                                                                                  \
  P(IWDG, IWDG, 0x40003000)                                                                                    \
  P(LPTIM1, LPTIM, 0x40007C00)                                                                                 \
  P(GPIOA, GPIO, 0x48000000)                                                                                   \
  P(GPIOB, GPIO, 0x48000400)                                                                                   \
  P(GPIOC, GPIO, 0x48000800)

#define POUR_CHIP_REGS(R)                                                                                      \
  R(RCC, CR, 0x00)                                                                                             \
  R(RCC, CFGR, 0x08)                                                                                           \
  R(RCC, PLLCFGR, 0x0C)                                                                                        \
  R(RCC, AHB2ENR, 0x4C)                                                                                        \
  R(RCC, APB1ENR1, 0x58)                                                                                       \
  R(RCC, APB2ENR, 0x60)                                                                                        \
  R(RCC, CCIPR, 0x88)                                                                                          \
  R(PWR, CR5, 0x80)                                                                                            \
  R(FLASH, ACR, 0x00)                                                                                          \
  R(FLASH, ECCR, 0x18)                                                                                         \
  R(FLASH, OPTR, 0x20)                                                                                         \
  R(IWDG, KR, 0x00)                                                                                            \
  R(IWDG, PR, 0x04)                                                                                            \
  R(IWDG, RLR, 0x08)                                                                                           \
  R(IWDG, SR, 0x0C)                                                                                            \
  R(LPTIM, ISR, 0x00)                                                                                          \
  R(LPTIM, CFGR, 0x0C)                                                                                         \
  R(LPTIM, CR, 0x10)                                                                                           \
  R(LPTIM, ARR, 0x18)                                                                                          \
  R(LPTIM, CNT, 0x1C)                                                                                          \
  R(GPIO, MODER, 0x00)                                                                                         \
  R(GPIO, OTYPER, 0x04)                                                                                        \
  R(GPIO, OSPEEDR, 0x08)                                                                                       \
  R(GPIO, PUPDR, 0x0C)                                                                                         \
  R(GPIO, IDR, 0x10)                                                                                           \
  R(GPIO, ODR, 0x14)                                                                                           \
  R(GPIO, BSRR, 0x18)                                                                                          \
  R(GPIO, AFRL, 0x20)                                                                                          \
  R(GPIO, AFRH, 0x24)

/* GPIO fields repeat per pin: pin n's field is at n x WIDTH (AFRH: (n - 8) x WIDTH); pins 0 and 15 are
 * checked, the stride between them follows. */
#define POUR_CHIP_FIELDS(F)                                                                                    \
  F(RCC, CR, HSION, 8, 1)                                                                                      \
  F(RCC, CR, HSIRDY, 10, 1)                                                                                    \
  F(RCC, CR, HSEON, 16, 1)                                                                                     \
  F(RCC, CR, HSERDY, 17, 1)                                                                                    \
  F(RCC, CR, HSEBYP, 18, 1)                                                                                    \
  F(RCC, CR, CSSON, 19, 1)                                                                                     \
  F(RCC, CR, PLLON, 24, 1)                                                                                     \
  F(RCC, CR, PLLRDY, 25, 1)                                                                                    \
  F(RCC, CFGR, SW, 0, 2)                                                                                       \
  F(RCC, CFGR, SWS, 2, 2)                                                                                      \
  F(RCC, CFGR, HPRE, 4, 4)                                                                                     \
  F(RCC, CFGR, PPRE1, 8, 3)                                                                                    \
  F(RCC, CFGR, PPRE2, 11, 3)                                                                                   \
  F(RCC, PLLCFGR, PLLSRC, 0, 2)                                                                                \
  F(RCC, PLLCFGR, PLLM, 4, 4)                                                                                  \
  F(RCC, PLLCFGR, PLLN, 8, 7)                                                                                  \
  F(RCC, PLLCFGR, PLLREN, 24, 1)                                                                               \
  F(RCC, PLLCFGR, PLLR, 25, 2)                                                                                 \
  F(RCC, AHB2ENR, GPIOAEN, 0, 1)                                                                               \
  F(RCC, AHB2ENR, GPIOBEN, 1, 1)                                                                               \
  F(RCC, AHB2ENR, GPIOCEN, 2, 1)                                                                               \
  F(RCC, AHB2ENR, ADC12EN, 13, 1)                                                                              \
  F(RCC, AHB2ENR, DAC3EN, 18, 1)                                                                               \
  F(RCC, APB1ENR1, TIM4EN, 2, 1)                                                                               \
  F(RCC, APB1ENR1, FDCANEN, 25, 1)                                                                             \
  F(RCC, APB1ENR1, PWREN, 28, 1)                                                                               \
  F(RCC, APB1ENR1, LPTIM1EN, 31, 1)                                                                            \
  F(RCC, APB2ENR, SYSCFGEN, 0, 1)                                                                              \
  F(RCC, APB2ENR, TIM1EN, 11, 1)                                                                               \
  F(RCC, CCIPR, LPTIM1SEL, 18, 2)                                                                              \
  F(RCC, CCIPR, FDCANSEL, 24, 2)                                                                               \
  F(PWR, CR5, R1MODE, 8, 1)                                                                                    \
  F(FLASH, ACR, LATENCY, 0, 4)                                                                                 \
  F(FLASH, ACR, PRFTEN, 8, 1)                                                                                  \
  F(FLASH, ACR, ICEN, 9, 1)                                                                                    \
  F(FLASH, ACR, DCEN, 10, 1)                                                                                   \
  F(FLASH, ECCR, ECCD, 31, 1)                                                                                  \
  F(FLASH, OPTR, N_BOOT1, 23, 1)                                                                               \
  F(FLASH, OPTR, N_SWBOOT0, 26, 1)                                                                             \
  F(FLASH, OPTR, N_BOOT0, 27, 1)                                                                               \
  F(IWDG, KR, KEY, 0, 16)                                                                                      \
  F(IWDG, PR, PR, 0, 3)                                                                                        \
  F(IWDG, RLR, RL, 0, 12)                                                                                      \
  F(IWDG, SR, PVU, 0, 1)                                                                                       \
  F(IWDG, SR, RVU, 1, 1)                                                                                       \
  F(IWDG, SR, WVU, 2, 1)                                                                                       \
  F(LPTIM, ISR, ARROK, 4, 1)                                                                                   \
  F(LPTIM, CFGR, PRESC, 9, 3)                                                                                  \
  F(LPTIM, CR, ENABLE, 0, 1)                                                                                   \
  F(LPTIM, CR, CNTSTRT, 2, 1)                                                                                  \
  F(LPTIM, ARR, ARR, 0, 16)                                                                                    \
  F(LPTIM, CNT, CNT, 0, 16)                                                                                    \
  F(GPIO, MODER, MODER0, 0, 2)                                                                                 \
  F(GPIO, MODER, MODER15, 30, 2)                                                                               \
  F(GPIO, OTYPER, OT0, 0, 1)                                                                                   \
  F(GPIO, OSPEEDR, OSPEEDR0, 0, 2)                                                                             \
  F(GPIO, OSPEEDR, OSPEEDR15, 30, 2)                                                                           \
  F(GPIO, PUPDR, PUPDR0, 0, 2)                                                                                 \
  F(GPIO, PUPDR, PUPDR15, 30, 2)                                                                               \
  F(GPIO, IDR, IDR0, 0, 1)                                                                                     \
  F(GPIO, IDR, IDR15, 15, 1)                                                                                   \
  F(GPIO, ODR, ODR0, 0, 1)                                                                                     \
  F(GPIO, ODR, ODR15, 15, 1)                                                                                   \
  F(GPIO, BSRR, BS0, 0, 1)                                                                                     \
  F(GPIO, BSRR, BR0, 16, 1)                                                                                    \
  F(GPIO, BSRR, BR15, 31, 1)                                                                                   \
  F(GPIO, AFRL, AFRL0, 0, 4)                                                                                   \
  F(GPIO, AFRL, AFRL7, 28, 4)                                                                                  \
  F(GPIO, AFRH, AFRH8, 0, 4)                                                                                   \
  F(GPIO, AFRH, AFRH15, 28, 4)

POUR_REGS_DECLARE(CHIP);

/* GPIO pin modes (MODER) and pulls (PUPDR), RM0440. */
#define POUR_GPIO_MODE_INPUT 0u
#define POUR_GPIO_MODE_OUTPUT 1u
#define POUR_GPIO_MODE_AF 2u
#define POUR_GPIO_MODE_ANALOG 3u
#define POUR_GPIO_PULL_NONE 0u
#define POUR_GPIO_PULL_UP 1u
#define POUR_GPIO_PULL_DOWN 2u
/* Output speeds (OSPEEDR), RM0440: 0 low (the reset value of most pins) .. 3 very high. */
#define POUR_GPIO_SPEED_LOW 0u
#define POUR_GPIO_SPEED_HIGH 2u

#endif /* POUR_STM32G431_REGS_H */
