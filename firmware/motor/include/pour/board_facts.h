/* SPDX-License-Identifier: MIT */
/* The ST B-G431B-ESC1 as ST built it: every fact about the board that the firmware's board configuration, the
 * simulator's model of its analog chain, the docs (docs/board.md, generated from this file by
 * tests/board/board_facts.py) and the tests use, each declared once here with its source.
 *
 * POUR_BOARD_FACTS rows: X(NAME, value, unit, what it is, source). Integers only (the firmware has no float):
 * the unit says the scale. POUR_BOARD_PINS rows: X(NAME, port, pin, owner, signal, af, use, on-board parts,
 * source), af -1 where the pin is not an alternate function (analog, a GPIO). The sources' short names:
 *   [mcsdk] ST's MCSDK 6.4.2 project generated for this board (public repository
 *           wshan1977/st_B-G431B-ESC1_controller: ElectronicSpeedControl_ESC-G4.ioc, Src/main.c, Src/mc_parameters.c,
 *           Inc/power_stage_parameters.h, Inc/drive_parameters.h, Inc/main.h)
 *   [sfoc]  SimpleFOC (simplefoc/Arduino-FOC): src/current_sense/hardware_specific/stm32/b_g431/, the board's example
 *   [stim]  FOC-Stim (diglet48/FOC-Stim) src/bsp/bsp_g431b_esc1.cpp and src/utils.cpp
 *   [duino] stm32duino's variant_B_G431B_ESC1.h (copyright ST: a net name for every pin)
 *   [ds]    the STM32G431 datasheet (DS12589); [an2606] ST's AN2606 (system-memory boot); [rm] RM0440
 * A row with an empty source does not compile (POUR_BOARD_FACT_SOURCED below), and the docs check refuses it. */
#ifndef POUR_BOARD_FACTS_H
#define POUR_BOARD_FACTS_H

#define POUR_BOARD_FACTS(X)                                                                                    \
  X(SHUNT_UOHM, 3000, "uOhm", "phase shunt, one per low side",                                                 \
    "[mcsdk] power_stage_parameters.h RSHUNT 0.003; [sfoc] example LowsideCurrentSense(0.003, ...)")           \
  X(PGA_GAIN, 16, "-", "OPAMP1..3: internal PGA, non-inverting gain 16, input/bias on VINM0 (PGA_GAIN 0b01011, VM_SEL PGA)", \
    "[mcsdk] main.c MX_OPAMPx_Init PGA_GAIN_16_OR_MINUS_15, PGA_CONNECT_INVERTINGINPUT_IO0_BIAS; .ioc OPAMP_PGAGAIN 16; [stim] configureOpamp") \
  X(INPUT_NETWORK_MILLI, 571, "1/1000", "the board's network from the shunt to the op-amp's VINP",            \
    "[mcsdk] .ioc WB_UI_GON 0.571; [sfoc] gain -64/7 = 16 x 4/7")                                             \
  X(AMP_GAIN_MILLI, 9140, "1/1000", "shunt voltage to ADC pin voltage, network x PGA (16 x 0.571)",           \
    "[mcsdk] power_stage_parameters.h AMPLIFICATION_GAIN 9.14, .ioc WB_UI_GAIN 9.136; [sfoc], [stim] 64/7")    \
  X(VINP_BIAS_UV, 128563, "uV", "op-amp input (and comparator input) at zero current",                       \
    "[mcsdk] .ioc WB_UI_VPOL_K 0.1285625")                                                                    \
  X(BIAS_MV, 2057, "mV", "op-amp output (ADC pin) at zero current: 16 x the input's bias",                    \
    "[mcsdk] .ioc WB_UI_VPOL 2.057 (the x16 entry of WB_UI_GAINLIST)")                                        \
  X(OFFSET_NOMINAL_COUNTS, 2553, "counts", "the bias in 12-bit counts of 3.3 V: 2.057 x 4096 / 3.3",          \
    "derived: BIAS_MV, ADC_VREF_MV")                                                                          \
  X(OFFSET_TOLERANCE_COUNTS, 100, "counts", "band of a healthy board's bias: 1 % resistors on the bias divider (+-1.4 %, 36 counts), the PGA's gain error and input offset x 16 (+-30 counts), margin", \
    "[ds] OPAMP PGA gain error and VIOFFSET; the network's parts not read (schematic): a margin, stated")     \
  X(CURRENT_SIGN, -1, "-", "phase current = sign x (ADC - bias): the ADC falls as current flows into the motor", \
    "[mcsdk] MCLib/G4xx/Src/r3_2_g4xx_pwm_curr_fdbk.c Ia = PhaseAOffset - ADC; [sfoc] example gain -64/7; [stim] gain -64/7")          \
  X(ADC_VREF_MV, 3300, "mV", "VDDA = VREF+ (ADC and DAC full scale)",                                         \
    "[mcsdk] .ioc ADC_REFERENCE_VOLTAGE, WB_UI_GAINLIST maxVRef 3.3; [stim] ADC_VOLTAGE 3.3")                  \
  X(VBUS_R_TOP_OHM, 169000, "Ohm", "bus divider, upper resistor (PA0)", "[stim] BSP_ReadVBus (18 + 169) / 18") \
  X(VBUS_R_BOTTOM_OHM, 18000, "Ohm", "bus divider, lower resistor", "[stim] BSP_ReadVBus (18 + 169) / 18")  \
  X(VBUS_DIVIDER_MILLI, 10389, "1/1000", "bus voltage / PA0 voltage = (169 + 18) / 18",                       \
    "[mcsdk] power_stage_parameters.h VBUS_PARTITIONING_FACTOR 0.09625565 (1 / 10.389); [stim]")              \
  X(NTC_R25_OHM, 10000, "Ohm", "power-stage NTC at 25 C, between 3.3 V and PB14", "[stim] utils.cpp ntc_voltage_to_temp R25 10000") \
  X(NTC_BETA_K, 3425, "K", "the NTC's B constant", "[stim] utils.cpp ntc_voltage_to_temp Beta 3425")          \
  X(NTC_R_BOTTOM_OHM, 4700, "Ohm", "resistor from PB14 to ground", "[stim] utils.cpp ntc_voltage_to_temp ResistorBalance 4700") \
  X(NTC_V0_MV, 1055, "mV", "PB14 at 25 C (3.3 x 4.7 / 14.7): the older ST profile's V0; MCSDK 6.4.2's 1.4 V does not fit the parts", \
    "ST's older B-G431B-ESC1 profile V0 1.055 V; [mcsdk] 6.4.2 power_stage_parameters.h V0_V 1.4, dV_dT 0.019; the parts [stim]") \
  X(NTC_DV_DT_UV_PER_C, 22700, "uV/C", "PB14's slope, linearised over the working range (the older ST profile)", \
    "ST's older B-G431B-ESC1 profile (22.7 mV/C; DESIGN.md rounds it to 23); the parts' slope at 25 C is 27.7 mV/C ([stim])") \
  X(HSE_HZ, 8000000, "Hz", "the crystal on PF0/PF1",                                                          \
    "[mcsdk] .ioc EXT_CLK_8_MHZ; main.c SystemClock_Config HSE, PLLM /2, PLLN 85, PLLR /2 = 170 MHz")        \
  X(DEADTIME_NS, 800, "ns", "TIM1's dead time per leg (the port's): at least ST's 750 ns in the timer and its 800 ns board figure", \
    "[mcsdk] drive_parameters.h SW_DEADTIME_NS 750 (LS_PWM_TIMER: the timer makes both), power_stage_parameters.h HW_DEAD_TIME_NS 800") \
  X(GATE_INPUT_ACTIVE_HIGH, 1, "bool", "L6387 HIN/LIN: a high input turns its switch on (CCxP = CCxNP = 0)",  \
    "[mcsdk] .ioc PHASE_UH..WL_POLARITY H_ACTIVE_HIGH / L_ACTIVE_HIGH, main.c OCPolarity/OCNPolarity HIGH")    \
  X(IDLE_HIGH_SIDE_ON, 0, "bool", "high sides at MOE = 0 (a break, OSSI): off (OISx = 0)",                   \
    "[mcsdk] .ioc HIGH_SIDE_IDLE_STATE false; main.c OCIdleState RESET")                                      \
  X(IDLE_LOW_SIDE_ON, 0, "bool", "low sides at MOE = 0: off (OISxN = 0); on would short a bus through a failed high side", \
    "[mcsdk] .ioc LOW_SIDE_IDLE_STATE false; main.c OCNIdleState RESET")                                      \
  X(BOARD_PEAK_MA, 40000, "mA", "the power stage's rated peak current", "[mcsdk] .ioc WB_UI_PW_BOARD_MAX_RATED_CURRENT 40") \
  X(BUS_MAX_MV, 28000, "mV", "highest bus voltage the board is rated for", "[mcsdk] .ioc WB_UI_PW_BOARD_MAX_VOLTAGE 28") \
  X(BUS_MIN_MV, 8000, "mV", "lowest bus voltage the board is rated for", "[mcsdk] .ioc WB_UI_PW_BOARD_MIN_VOLTAGE 8") \
  X(BOOT0_PULLUP_OHM, 10000, "Ohm", "pull-up from PB8 (BOOT0, J8's Z) to 3.3 V",                              \
    "issue 35's reading of UM2516's schematic; [duino] PB8 HALL3/ENCODER_Z")                                 \
  X(FLASH_PAGE_ERASE_MAX_US, 24470, "us", "a 2 KB page erase, worst case (the single-bank G431 stalls fetches meanwhile)", \
    "[ds] flash memory characteristics tERASE 22.02 ms typ., 24.47 ms max.")                                 \
  X(LSI_MAX_HZ, 34000, "Hz", "LSI's fastest (the IWDG's clock): the shortest a timeout can be", "[ds] LSI oscillator 29.5 .. 34 kHz")

/* The pins the port uses and the on-board parts on pins it must leave alone. */
#define POUR_BOARD_PINS(X)                                                                                     \
  X(PWM_UH, A, 8, TIM1, CH1, 6, "phase U high gate", "L6387 HIN", "[mcsdk] main.h M1_PWM_UH; [duino] PHASE_UH") \
  X(PWM_VH, A, 9, TIM1, CH2, 6, "phase V high gate", "L6387 HIN", "[mcsdk] main.h M1_PWM_VH; [duino] PHASE_VH") \
  X(PWM_WH, A, 10, TIM1, CH3, 6, "phase W high gate", "L6387 HIN", "[mcsdk] main.h M1_PWM_WH; [duino] PHASE_WH") \
  X(PWM_UL, C, 13, TIM1, CH1N, 4, "phase U low gate", "L6387 LIN", "[mcsdk] main.h M1_PWM_UL; [duino] PHASE_UL") \
  X(PWM_VL, A, 12, TIM1, CH2N, 6, "phase V low gate", "L6387 LIN", "[mcsdk] main.h M1_PWM_VL; [duino] PHASE_VL") \
  X(PWM_WL, B, 15, TIM1, CH3N, 4, "phase W low gate", "L6387 LIN", "[mcsdk] main.h M1_PWM_WL; [duino] PHASE_WL") \
  X(ENC_A, B, 6, TIM4, CH1, 2, "motor encoder A (J8)", "J8", "[duino] HALL1/ENCODER_A")                        \
  X(ENC_B, B, 7, TIM4, CH2, 2, "motor encoder B (J8)", "J8", "[duino] HALL2/ENCODER_B")                        \
  X(CAN_RX, A, 11, FDCAN1, RX, 9, "FDCAN1 RX", "CAN transceiver", "[duino] CAN_RX")                           \
  X(CAN_TX, B, 9, FDCAN1, TX, 9, "FDCAN1 TX", "CAN transceiver", "[duino] CAN_TX")                            \
  X(SHUNT_U, A, 1, OPAMP1, VINP0, -1, "U shunt signal (OPAMP1 VINP0, COMP1 INP)", "shunt network", "[mcsdk] main.h M1_CURR_SHUNT_U, .ioc OPAMP1 PA1") \
  X(SHUNT_U_M, A, 3, OPAMP1, VINM0, -1, "U shunt bias (OPAMP1 VINM0)", "shunt network", "[mcsdk] main.h M1_OPAMP1_INT_GAIN, .ioc PA3 VINM0") \
  X(AMP_U, A, 2, OPAMP1, VOUT, -1, "U amplifier out, ADC1 IN3", "-", "[mcsdk] main.h M1_OPAMP1_OUT, main.c ADC1 CH3") \
  X(SHUNT_V, A, 7, OPAMP2, VINP0, -1, "V shunt signal (OPAMP2 VINP0, COMP2 INP)", "shunt network", "[mcsdk] main.h M1_CURR_SHUNT_V") \
  X(SHUNT_V_M, A, 5, OPAMP2, VINM0, -1, "V shunt bias (OPAMP2 VINM0)", "shunt network", "[mcsdk] main.h M1_OPAMP2_INT_GAIN") \
  X(AMP_V, A, 6, OPAMP2, VOUT, -1, "V amplifier out, ADC2 IN3", "-", "[mcsdk] main.h M1_OPAMP2_OUT, main.c ADC2 CH3") \
  X(SHUNT_W, B, 0, OPAMP3, VINP0, -1, "W shunt signal (OPAMP3 VINP0, COMP4 INP)", "shunt network", "[mcsdk] main.h M1_CURR_SHUNT_W") \
  X(SHUNT_W_M, B, 2, OPAMP3, VINM0, -1, "W shunt bias (OPAMP3 VINM0)", "shunt network", "[mcsdk] main.h M1_OPAMP3_INT_GAIN") \
  X(AMP_W, B, 1, OPAMP3, VOUT, -1, "W amplifier out, ADC1 IN12", "-", "[mcsdk] main.h M1_OPAMP3_OUT, mc_parameters.c ADC1 JSQ 12") \
  X(VBUS, A, 0, ADC1, IN1, -1, "bus divider, ADC1 IN1", "169 k / 18 k divider", "[mcsdk] main.h M1_BUS_VOLTAGE, main.c ADC1 CH1") \
  X(NTC, B, 14, ADC1, IN5, -1, "power-stage NTC, ADC1 IN5", "10 k NTC, 4.7 k", "[mcsdk] main.h M1_TEMPERATURE, .ioc TEMP_FDBK_CHANNEL 5") \
  X(BRAKE, B, 3, GPIO, OUT, -1, "brake release out, high = released (external 10 k pull-down)", "ST-LINK VCP RX (daughterboard)", \
    "[duino] USART2_TX; JTDO, no pull at reset [rm]; not a bootloader pin [an2606]")                         \
  X(POWER, A, 15, GPIO, OUT, -1, "power-stage enable out, high = on (external 4.7 k pull-down)", "PWM-input pad", \
    "[duino] PWM, [mcsdk] M1_PWM_INPUT; JTDI pull-up 25..55 k at reset [ds]: 4.7 k holds it under 0.52 V; not a bootloader pin [an2606]") \
  X(ESTOP, B, 8, GPIO, IN, -1, "e-stop in, high = asserted: a normally-closed contact to ground", "10 k pull-up (BOOT0)", \
    "[duino] HALL3/ENCODER_Z; the pull-up: BOOT0_PULLUP_OHM")                                                \
  X(CAN_SHDN, C, 11, GPIO, OUT, -1, "CAN transceiver shutdown, low = on", "CAN transceiver", "[duino] CAN_SHDN") \
  X(CAN_TERM, C, 14, GPIO, OUT, -1, "CAN termination switch, high = on", "termination", "[duino] CAN_TERM")  \
  X(LED, C, 6, GPIO, OUT, -1, "LED (red), high = on", "LED", "[duino] LED_RED")                              \
  X(POT, B, 12, ADC1, IN11, -1, "not used: the on-board potentiometer's wiper", "potentiometer", "[stim] ADC1_CHANNEL_POTENTIOMETER PB12; [duino] POTENTIOMETER") \
  X(BUTTON, C, 10, GPIO, IN, -1, "not used: the user button (USART3 TX in the ROM bootloader)", "button", "[mcsdk] main.h Start_Stop PC10; [an2606]") \
  X(BEMF_U, A, 4, ADC2, IN17, -1, "not used: phase U back-EMF divider", "divider", "[duino] BEMF1")         \
  X(BEMF_V, C, 4, ADC2, IN5, -1, "not used: phase V back-EMF divider", "divider", "[duino] BEMF2")          \
  X(BEMF_W, B, 11, ADC1, IN14, -1, "not used: phase W back-EMF divider", "divider", "[duino] BEMF3")        \
  X(BEMF_EN, B, 5, GPIO, OUT, -1, "not used: enables the back-EMF dividers", "transistor", "[duino] GPIO_BEMF") \
  X(VCP_RX, B, 4, USART2, RX, 7, "not used: ST-LINK VCP TX into the MCU (NJTRST pull-up at reset)", "ST-LINK", "[mcsdk] main.h UART_RX PB4; [duino] USART2_RX")

/* Each fact as an enum constant POUR_BOARD_<NAME>. */
#define POUR_BOARD_FACT_ENUM(name, value, unit, what, source) POUR_BOARD_##name = (value),
enum { POUR_BOARD_FACTS(POUR_BOARD_FACT_ENUM) };

/* Each pin as POUR_BOARD_PIN_<NAME>_PORT (0 = port A), _PIN and _AF (-1: none). */
enum { POUR_BOARD_PORT_A = 0, POUR_BOARD_PORT_B = 1, POUR_BOARD_PORT_C = 2 };
#define POUR_BOARD_PIN_ENUM(name, port, pin, owner, signal, af, use, parts, source)                           \
  POUR_BOARD_PIN_##name##_PORT = POUR_BOARD_PORT_##port, POUR_BOARD_PIN_##name##_PIN = (pin),                   \
  POUR_BOARD_PIN_##name##_AF = (af),
enum { POUR_BOARD_PINS(POUR_BOARD_PIN_ENUM) };

/* A source is at least a few characters: an empty one stops the build here. */
#define POUR_BOARD_FACT_SOURCED(name, value, unit, what, source)                                              \
  typedef char pour_board_fact_##name##_has_a_source[(sizeof(source) > 4u) ? 1 : -1];
#define POUR_BOARD_PIN_SOURCED(name, port, pin, owner, signal, af, use, parts, source)                        \
  typedef char pour_board_pin_##name##_has_a_source[(sizeof(source) > 4u) ? 1 : -1];
POUR_BOARD_FACTS(POUR_BOARD_FACT_SOURCED)
POUR_BOARD_PINS(POUR_BOARD_PIN_SOURCED)

#endif /* POUR_BOARD_FACTS_H */
