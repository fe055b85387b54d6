// SPDX-License-Identifier: MIT
// The virtual B-G431B-ESC1's analog side, built in one call for the board (issue 37): the models of TIM1,
// ADC1/ADC2, OPAMP1..3, COMP1..4, DAC3, TIM4 and LPTIM1, and the plant behind them (host_sim's motor,
// inverter and bus, through the board's shunts, op-amp networks and dividers as ST built them).
//
//   vb::AnalogSet set = vb::make_analog_models(vb::AnalogOptions{});
//   for (auto& p : set.peripherals) board.add(std::move(p));   // each one vb::Peripheral, its window
//   // the plant needs no call: TIM1 steps it to each model's advance(); set.plant reads the state.
#ifndef POUR_VB_ANALOG_HPP
#define POUR_VB_ANALOG_HPP

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "peripheral.hpp"

namespace vb {

class Tim1;
class Adc;
class Adc12Common;
class Opamps;
class Dac3;
class Comps;
class Tim4;
class Lptim1;

struct AnalogOptions {
  uint64_t seed = 1;                // the converters' noise and the motor model's randomness
  double supply_v = 0.0;            // bench supply [V]; 0: the simulator's default config (supply_voltage)
  double temperature_c = 25.0;      // the power stage's NTC
  double pot_fraction = 0.5;        // the potentiometer's wiper, 0 .. 1 of 3.3 V
  double adc_noise_counts = 1.0;    // RMS noise of each conversion
  // The rotor: the motor model's inertia and a load; locked holds it still (the stall test, a blocked rig).
  double rotor_inertia = 0.0;       // [kg m^2]; 0: the simulator's motor_rotor_inertia
  double viscous_nms = 1e-5;        // [N m s / rad] at the motor, assumed
  double load_torque_nm = 0.0;      // at the motor
  bool locked_rotor = false;
  double lptim_kernel_hz = 16e6;    // LPTIM1SEL = HSI16 as the firmware selects it (RCC is vboard's model)
  // Faults injected in the models.
  double fault_phase_overcurrent_a = 0.0;  // added to phase U's shunt current from fault_at_s on
  double fault_at_s = 0.0;
  bool fault_encoder_stuck = false;        // the count stops (from fault_at_s)
  // RM0440 DAC_MCR HFSEL: required above 80 MHz of AHB clock. Strict: the board stops when DAC3 is enabled
  // without it at a faster HCLK (the image as shipped does not set it; see the report).
  bool strict_dac_hfsel = false;
};

// The plant: the simulator's motor model (host_sim motor_model.cpp: PMSM, inverter averaged over a PWM
// period, bus capacitor and supply), a rotor, and the board's analog nodes that the models read.
class Plant {
 public:
  explicit Plant(const AnalogOptions& o);
  ~Plant();
  void connect(Tim1* tim1, Tim4* tim4, Comps* comps, Opamps* opamps) {
    tim1_ = tim1; tim4_ = tim4; comps_ = comps; opamps_ = opamps;
  }
  void reset();
  // The load on the shaft beyond the options' constant one, e.g. host_sim's bucket through the gear: torque
  // at the motor [N m] from time [s], shaft angle [rad] and speed [rad/s]; called once per PWM period.
  using Load = std::function<double(double t, double theta_m, double omega_m)>;
  void set_load(Load load) { load_ = std::move(load); }
  // Run whole PWM periods of the motor model up to the link's time (the duties from TIM1's active compares).
  void step_to_cycle(const BoardLink* link);
  // The cycle at which the next period starts (for the board's next_event).
  uint64_t next_step_cycle(const BoardLink* link) const;

  // The board's analog nodes [V] (board_facts.h; the sources beside each in plant.cpp).
  double shunt_vinp(int phase) const;  // OPAMPk VINP0 and COMP INP: the shunt network's output
  double vinm0(int phase) const;       // OPAMPk VINM0 pin
  double vbus_pin() const;             // PA0
  double ntc_pin() const;              // PB14
  double pot_pin() const;              // PB12
  double vdda() const;                 // 3.3 V
  // What drives input `channel` of ADC`adc` (1, 2) [V]; false when nothing does (RM0440 table 166 / 167,
  // the pins as the board wires them: board_facts.h POUR_BOARD_PINS).
  bool adc_input(int adc, uint32_t channel, double* volts) const;
  double adc_noise();                  // one seeded sample of the converters' noise [counts]
  void set_sample_cycle(uint64_t cycle) { sample_cycle_ = cycle; }  // the instant the next reads are for

  // State, for the tests and the board's telemetry.
  double phase_current(int k) const;   // into the motor [A], the fault included
  double vbus() const;
  double omega() const { return omega_; }  // motor shaft [rad/s]
  double theta() const { return theta_; }  // motor shaft [rad] since reset
  double time_s() const { return t_; }
  uint64_t periods() const { return periods_; }
  double torque() const { return torque_; }
  double r_phase() const;
  double l_phase() const;  // [H], the d axis's (the motor model's ld = lq)
  double pwm_hz() const;
  int encoder_cpr() const;
  int pole_pairs() const;
  double deadtime_s() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  AnalogOptions o_;
  Tim1* tim1_ = nullptr;
  Tim4* tim4_ = nullptr;
  Comps* comps_ = nullptr;
  Opamps* opamps_ = nullptr;
  uint64_t sample_cycle_ = 0;
  Load load_;
  double t_ = 0.0, omega_ = 0.0, theta_ = 0.0, torque_ = 0.0;
  uint64_t periods_ = 0;
  uint64_t last_cycles_ = 0;
  double seconds_ = 0.0;
  int last_encoder_ = 0;
};

struct AnalogSet {
  std::vector<std::unique_ptr<Peripheral>> peripherals;  // owned by the board once moved there
  std::unique_ptr<Plant> plant;                          // stays with the caller; the models point into it
  // Non-owning views, valid while the peripherals live.
  Tim1* tim1 = nullptr;
  Adc* adc1 = nullptr;
  Adc* adc2 = nullptr;
  Adc12Common* adc_common = nullptr;
  Opamps* opamp = nullptr;
  Dac3* dac3 = nullptr;
  Comps* comp = nullptr;
  Tim4* tim4 = nullptr;
  Lptim1* lptim1 = nullptr;
};

AnalogSet make_analog_models(const AnalogOptions& options);

}  // namespace vb

#endif
