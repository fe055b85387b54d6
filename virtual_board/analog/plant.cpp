// SPDX-License-Identifier: MIT
// The plant behind the virtual board's analog models: host_sim's motor model (motor_model.cpp: the PMSM in
// dq, the inverter averaged over each PWM period from the three duties and the bus, with the dead time's
// error; the bus capacitor and the supply) stepped once per PWM period in lockstep with the emulated
// clock, a rotor (inertia, viscous friction, a load), and the board's analog nodes as ST built them.
// The analog chain is the board's (pour/board_facts.h, each fact's source there), not the firmware's belief:
//   shunt network: VINP = VINP_BIAS + NETWORK x R_shunt x I_shunt, the shunt's current negative as the
//     phase current flows into the motor (CURRENT_SIGN -1: ADC falls with it), while the leg's low side
//     conducts; the PGA on it (x16) gives BIAS_MV at zero current.
//   VINM0 at 0 V DC: the output's bias is 16 x the input's (BIAS_MV = PGA_GAIN x VINP_BIAS_UV, both from
//     ST's MCSDK board description), which the PGA's "foot on VINM0" mode gives only with VINM0 at ground.
//   bus: PA0 = Vbus x 18 k / (169 k + 18 k); NTC: PB14 = 3.3 x 4.7 k / (4.7 k + R_NTC(T)), R_NTC from
//     R25 and B; the potentiometer's wiper on PB12 between 0 and 3.3 V.
#include <cmath>
#include <random>

#include "analog.hpp"
#include "foc_drive.hpp"
#include "models.hpp"
#include "motor_model.hpp"
#include "pour/board_facts.h"
#include "pour/drive.h"
#include "poursim/poursim.h"

namespace vb {

namespace {
constexpr double kTwoPi = 6.283185307179586;
constexpr double VDDA = POUR_BOARD_ADC_VREF_MV * 1e-3;
constexpr double SHUNT = POUR_BOARD_SHUNT_UOHM * 1e-6;
constexpr double NETWORK = POUR_BOARD_INPUT_NETWORK_MILLI * 1e-3;
constexpr double VINP_BIAS = POUR_BOARD_VINP_BIAS_UV * 1e-6;
}  // namespace

struct Plant::Impl {
  poursim::MotorParams params;
  poursim::MotorModel model;
  std::mt19937_64 rng;
  std::normal_distribution<double> noise{0.0, 1.0};
  double inertia = 2.4e-5;
};

Plant::Plant(const AnalogOptions& o) : impl_(new Impl), o_(o) { reset(); }
Plant::~Plant() = default;

void Plant::reset() {
  const poursim_config_t c = poursim_default_config();
  const pour_drive_config_t fw = pour_drive_default_config();
  impl_->params = poursim::motor_params(fw, c);
  if (o_.supply_v > 0.0) impl_->params.supply_v = o_.supply_v;
  impl_->inertia = o_.rotor_inertia > 0.0 ? o_.rotor_inertia : c.motor_rotor_inertia;
  impl_->model.reset(impl_->params, o_.seed, poursim::MotorFault::None);
  impl_->rng.seed(o_.seed ^ 0x5EEDA7A1ULL);
  t_ = omega_ = theta_ = torque_ = 0.0;
  periods_ = 0;
  last_cycles_ = 0;
  seconds_ = 0.0;
  last_encoder_ = 0;
  sample_cycle_ = 0;
}

double Plant::pwm_hz() const { return impl_->params.pwm_hz; }
double Plant::r_phase() const { return impl_->params.r_phase; }
double Plant::l_phase() const { return impl_->params.ld; }
int Plant::encoder_cpr() const { return impl_->params.encoder_cpr; }
int Plant::pole_pairs() const { return impl_->params.pole_pairs; }
double Plant::deadtime_s() const { return impl_->params.deadtime_s; }
double Plant::vbus() const { return impl_->model.vbus(); }
double Plant::vdda() const { return VDDA; }
double Plant::adc_noise() { return o_.adc_noise_counts * impl_->noise(impl_->rng); }

double Plant::phase_current(int k) const {
  double i = impl_->model.phase_current(k);
  if (k == 0 && o_.fault_phase_overcurrent_a != 0.0 && t_ >= o_.fault_at_s && tim1_ != nullptr && tim1_->outputs_enabled()) {
    i += o_.fault_phase_overcurrent_a;  // a short's current flows only while the bridge switches
  }
  return i;
}

double Plant::shunt_vinp(int phase) const {
  // The shunt carries the phase current while the low side conducts (at the PWM centre, where the ADC
  // samples); with the high side on it carries none.
  const bool low_on = tim1_ != nullptr && tim1_->low_side_on_at(phase, sample_cycle_);
  const double i_shunt = low_on ? POUR_BOARD_CURRENT_SIGN * phase_current(phase) : 0.0;
  return VINP_BIAS + NETWORK * SHUNT * i_shunt;
}

double Plant::vinm0(int) const { return 0.0; }

double Plant::vbus_pin() const {
  return vbus() * POUR_BOARD_VBUS_R_BOTTOM_OHM / static_cast<double>(POUR_BOARD_VBUS_R_TOP_OHM + POUR_BOARD_VBUS_R_BOTTOM_OHM);
}

double Plant::ntc_pin() const {
  const double t_k = o_.temperature_c + 273.15;
  const double r = POUR_BOARD_NTC_R25_OHM * std::exp(POUR_BOARD_NTC_BETA_K * (1.0 / t_k - 1.0 / 298.15));
  return VDDA * POUR_BOARD_NTC_R_BOTTOM_OHM / (POUR_BOARD_NTC_R_BOTTOM_OHM + r);
}

double Plant::pot_pin() const { return VDDA * std::fmin(std::fmax(o_.pot_fraction, 0.0), 1.0); }

bool Plant::adc_input(int adc, uint32_t channel, double* volts) const {
  // RM0440 tables 166 / 167 (ADC1 / ADC2 channels) and the board's pins (board_facts.h POUR_BOARD_PINS):
  // ADC1: IN1 PA0 bus, IN3 PA2 OPAMP1 VOUT, IN5 PB14 NTC, IN11 PB12 pot, IN12 PB1 OPAMP3 VOUT,
  //       IN13 OPAMP1 internal output; ADC2: IN3 PA6 OPAMP2 VOUT, IN16 OPAMP2 internal, IN18 OPAMP3 internal.
  auto opamp = [&](int k, bool internal) {
    if (opamps_ == nullptr) return false;
    const bool to_internal = ((opamps_->csr(k) >> 8u) & 1u) != 0u;  // OPAINTOEN
    if (to_internal != internal) return false;
    return opamps_->output(k, volts);
  };
  if (adc == 1) {
    switch (channel) {
      case 1: *volts = vbus_pin(); return true;
      case 3: return opamp(0, false);
      case 5: *volts = ntc_pin(); return true;
      case 11: *volts = pot_pin(); return true;
      case 12: return opamp(2, false);
      case 13: return opamp(0, true);
      default: return false;
    }
  }
  switch (channel) {
    case 3: return opamp(1, false);
    case 16: return opamp(1, true);
    case 18: return opamp(2, true);
    default: return false;
  }
}

uint64_t Plant::next_step_cycle(const BoardLink* link) const {
  // Seconds to the next period's start, at the present clock.
  const double ts = 1.0 / impl_->params.pwm_hz;
  const double next = static_cast<double>(periods_ + 1u) * ts;
  const uint64_t c = link->cycles();
  const double now = seconds_ + static_cast<double>(c - last_cycles_) / link->hclk_hz();
  const double wait = next - now;
  return c + (wait <= 0.0 ? 0u : static_cast<uint64_t>(std::ceil(wait * link->hclk_hz())));
}

void Plant::step_to_cycle(const BoardLink* link) {
  const uint64_t c = link->cycles();
  if (c > last_cycles_) {
    seconds_ += static_cast<double>(c - last_cycles_) / link->hclk_hz();
    last_cycles_ = c;
  }
  const double ts = 1.0 / impl_->params.pwm_hz;
  while (static_cast<double>(periods_ + 1u) * ts <= seconds_ + 1e-12) {
    double d[3] = {0.5, 0.5, 0.5};
    bool on = false;
    if (tim1_ != nullptr) {
      for (int k = 0; k < 3; ++k) d[k] = tim1_->duty(k);
      on = tim1_->outputs_enabled();
    }
    const double w = o_.locked_rotor ? 0.0 : omega_;
    torque_ = impl_->model.period(d, on, w);
    theta_ += w * ts;
    if (!o_.locked_rotor) {
      const double extra = load_ ? load_(t_, theta_, omega_) : 0.0;
      const double acc = (torque_ - o_.viscous_nms * omega_ - o_.load_torque_nm - extra) / impl_->inertia;
      omega_ += acc * ts;
    }
    ++periods_;
    t_ = static_cast<double>(periods_) * ts;
    // The encoder: the x4 count of the shaft's angle (encoder_cpr counts a turn), its change to TIM4.
    const int count = static_cast<int>(std::floor(theta_ / kTwoPi * impl_->params.encoder_cpr));
    const bool stuck = o_.fault_encoder_stuck && t_ >= o_.fault_at_s;
    if (!stuck) {
      if (tim4_ != nullptr) tim4_->edges(count - last_encoder_);
      last_encoder_ = count;
    }
    sample_cycle_ = c;
    if (comps_ != nullptr) comps_->evaluate();
  }
  sample_cycle_ = c;
}

// ---------------------------------------------------------------------------------------------- factory
namespace {
void adc_trigger(void* ctx, uint64_t cycle) { static_cast<Adc*>(ctx)->trigger(cycle); }
}  // namespace

AnalogSet make_analog_models(const AnalogOptions& options) {
  AnalogSet s;
  s.plant.reset(new Plant(options));
  auto tim1 = std::make_unique<Tim1>();
  auto adc1 = std::make_unique<Adc>(1, 0x50000000u);
  auto adc2 = std::make_unique<Adc>(2, 0x50000100u);
  auto common = std::make_unique<Adc12Common>();
  auto opamp = std::make_unique<Opamps>();
  auto dac3 = std::make_unique<Dac3>();
  auto comp = std::make_unique<Comps>();
  auto tim4 = std::make_unique<Tim4>();
  auto lptim1 = std::make_unique<Lptim1>(options.lptim_kernel_hz);
  s.tim1 = tim1.get();
  s.adc1 = adc1.get();
  s.adc2 = adc2.get();
  s.adc_common = common.get();
  s.opamp = opamp.get();
  s.dac3 = dac3.get();
  s.comp = comp.get();
  s.tim4 = tim4.get();
  s.lptim1 = lptim1.get();
  Plant* plant = s.plant.get();
  plant->connect(s.tim1, s.tim4, s.comp, s.opamp);
  s.tim1->connect(plant, s.comp);
  s.tim1->add_trgo2_sink(adc_trigger, s.adc1);
  s.tim1->add_trgo2_sink(adc_trigger, s.adc2);
  s.adc1->connect(s.adc_common, plant, s.adc2);
  s.adc2->connect(s.adc_common, plant, s.adc1);
  s.opamp->connect(plant);
  s.dac3->connect(s.comp, options.strict_dac_hfsel);
  s.comp->connect(plant, s.dac3, s.tim1, s.opamp);
  s.peripherals.push_back(std::move(tim1));
  s.peripherals.push_back(std::move(adc1));
  s.peripherals.push_back(std::move(adc2));
  s.peripherals.push_back(std::move(common));
  s.peripherals.push_back(std::move(opamp));
  s.peripherals.push_back(std::move(dac3));
  s.peripherals.push_back(std::move(comp));
  s.peripherals.push_back(std::move(tim4));
  s.peripherals.push_back(std::move(lptim1));
  for (auto& p : s.peripherals) p->reset();
  return s;
}

}  // namespace vb
