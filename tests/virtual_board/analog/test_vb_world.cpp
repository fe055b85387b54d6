// SPDX-License-Identifier: MIT
// The plant's rotor through the gear to host_sim's bucket world (world_coupling.hpp), without an emulated
// CPU: TIM1's compares set a voltage vector 90 electrical degrees ahead of the rotor (from TIM4's count)
// at a fixed amplitude, which the motor model turns into a positive torque: the bucket tilts toward the
// target and liquid leaves it. With zero duties and the holding brake the bucket stays put; a seed repeats
// exactly (the world's trajectory hash and the plant's shaft).
#include "setup.hpp"
#include "world_coupling.hpp"

using namespace vbt;

namespace {
constexpr double kPi = 3.14159265358979;

void compares(Board& b, const double d[3]) {
  b.w("TIM1", T1_CCR1, static_cast<uint32_t>(std::lround(d[0] * ARR_20KHZ)));
  b.w("TIM1", T1_CCR2, static_cast<uint32_t>(std::lround(d[1] * ARR_20KHZ)));
  b.w("TIM1", T1_CCR3, static_cast<uint32_t>(std::lround(d[2] * ARR_20KHZ)));
}

struct Run {
  double theta_max = 0.0, theta_end = 0.0, remaining0 = 0.0, remaining = 0.0, poured = 0.0, spilled = 0.0;
  double shaft = 0.0;
  double t_leaves = -1.0, peak_gear_nm = 0.0;  // first time 1 % of the liquid is out [s]; peak |gear torque|
  uint64_t hash = 0;
  uint32_t steps = 0;
  vb::WorldSensors sensors;
  pour_can_frame_t frame{};
  bool packed = false;
  bool ok = false;
};

// The vector `amplitude` ahead of the rotor (negative: 90 degrees behind it; 0: all three compares at 0, every
// low side on), from TIM4's count, one PWM period per step().
class Drive {
 public:
  Drive(Board& b, double amplitude) : b_(b), a_(amplitude), cpr_(b.set.plant->encoder_cpr()), pp_(b.set.plant->pole_pairs()) {
    b.w("TIM4", 0x08, 3u);
    b.w("TIM4", 0x18, 1u | (1u << 8));
    b.w("TIM4", 0x00, 1u);
    if (amplitude != 0.0) tim1_pwm(b, ARR_20KHZ / 2, ARR_20KHZ / 2, ARR_20KHZ / 2);
    else tim1_pwm(b, 0, 0, 0);
  }
  void step() {
    if (a_ != 0.0) {
      const uint16_t c = static_cast<uint16_t>(b_.r("TIM4", 0x24));
      total_ += static_cast<int16_t>(static_cast<uint16_t>(c - last_));
      last_ = c;
      const double th = 2.0 * kPi * static_cast<double>(total_) / cpr_ * pp_ + kPi / 2.0;
      double d[3];
      for (int k = 0; k < 3; ++k) d[k] = 0.5 + a_ * std::cos(th - 2.0 * kPi * k / 3.0);
      compares(b_, d);
    }
    b_.run_s(50e-6);
  }

 private:
  Board& b_;
  double a_;
  int cpr_, pp_;
  int32_t total_ = 0;
  uint16_t last_ = 0;
};

// `amplitude` of the vector, `seconds` of it.
Run run(double amplitude, double seconds, bool brake, uint32_t seed) {
  vb::AnalogOptions o;
  o.seed = seed;
  Board b(o);
  vb::WorldCouplingOptions wo;
  wo.seed = seed;
  wo.brake = brake;
  vb::WorldCoupling world(wo, b.set.plant.get());
  Run r;
  if (!world.ok()) {
    std::printf("world: %s\n", world.error().c_str());
    return r;
  }
  r.remaining0 = world.remaining();
  Drive drive(b, amplitude);
  const int periods = static_cast<int>(seconds * 20000.0);
  for (int n = 0; n < periods && world.ok(); ++n) {
    drive.step();
    r.theta_max = std::fmax(r.theta_max, std::fabs(world.bucket_theta()));
    r.peak_gear_nm = std::fmax(r.peak_gear_nm, std::fabs(world.gear_torque()));
    if (r.t_leaves < 0.0 && world.remaining() < r.remaining0 - 0.01) r.t_leaves = world.obs().t;
  }
  r.ok = world.ok();
  if (!r.ok) std::printf("world: %s\n", world.error().c_str());
  r.theta_end = world.bucket_theta();
  r.remaining = world.remaining();
  r.poured = world.poured();
  r.spilled = world.spilled();
  r.shaft = b.set.plant->theta();
  r.hash = world.trajectory_hash();
  r.steps = world.steps();
  r.sensors = world.sensors();
  r.packed = world.sensors_frame(1u, &r.frame);
  return r;
}
}  // namespace

int main() {
  {  // A positive torque: the bucket tilts toward the target and pours.
    const Run r = run(0.12, 4.0, false, 1u);
    CHECK(r.ok, "the world ran");
    CHECK(r.steps >= 3999u && r.steps <= 4000u, "lockstep: %u physics steps in 4 s", r.steps);
    CHECK(r.theta_end > 0.5, "the bucket tilted toward the target: %.3f rad", r.theta_end);
    CHECK(r.remaining < r.remaining0 - 0.05, "liquid left the bucket: %.3f of %.3f remains", r.remaining, r.remaining0);
    CHECK(std::fabs(r.shaft / 20.0 - r.theta_end) < 0.02, "the shaft follows through the gear: %.4f vs %.4f rad",
          r.shaft / 20.0, r.theta_end);
    CHECK(r.sensors.scale_target_g > 0, "the target's scale reads the poured liquid: %d g", r.sensors.scale_target_g);
    pour_can_sensors_t m{};
    CHECK(r.packed && pour_can_unpack_sensors(&r.frame, &m) == POUR_CAN_RX_OK, "the Sensors frame packs and unpacks");
    CHECK(m.encoder == r.sensors.encoder && m.scale_target_g == r.sensors.scale_target_g &&
              m.scale_rotating_g == r.sensors.scale_rotating_g && m.seq_low == (r.sensors.step & 0xFFu),
          "the frame carries the sample: encoder %u / %u, target %d / %d g", m.encoder, r.sensors.encoder, m.scale_target_g,
          r.sensors.scale_target_g);
    const double enc_rad = static_cast<double>(r.sensors.encoder) * 2.0 * kPi / (1u << poursim_default_config().encoder_bits);
    CHECK(std::fabs(enc_rad - r.theta_end) < 0.01, "the output encoder reads the tilt: %.4f vs %.4f rad", enc_rad, r.theta_end);
    // The motor's peak 1.35 N m x N 20 (config_fields.h motor_peak_torque's note), with 20 % for the gear's spring.
    CHECK(r.peak_gear_nm < 1.35 * 20.0 * 1.2, "the gear carries at most about the motor's peak x N: %.2f N m", r.peak_gear_nm);
    std::printf("pour: 1 %% out at t = %.3f s, peak gear torque %.2f N m; theta %.3f rad (max %.3f), remaining %.3f of %.3f, poured %.3f, spilled %.3f, shaft/N %.4f rad, "
                "scales %d g / %d g at step %u\n",
                r.t_leaves, r.peak_gear_nm, r.theta_end, r.theta_max, r.remaining, r.remaining0, r.poured, r.spilled, r.shaft / 20.0,
                r.sensors.scale_rotating_g, r.sensors.scale_target_g, r.sensors.step);
  }
  {  // The vector behind the rotor: a negative torque, the bucket goes to its lower stop (-5 deg).
    const Run r = run(-0.12, 0.5, false, 1u);
    const double lo = poursim_default_config().theta_min;
    CHECK(r.ok && std::fabs(r.theta_end - lo) < 0.01, "at the lower stop: %.4f rad (stop %.4f)", r.theta_end, lo);
    std::printf("negative torque: theta %.4f rad, the stop at %.4f rad\n", r.theta_end, lo);
  }
  {  // Zero duties, the brake engaged: held within 1 degree for 1 s.
    const Run r = run(0.0, 1.0, true, 1u);
    CHECK(r.ok, "the world ran");
    CHECK(r.theta_max < 1.0 * kPi / 180.0, "held: |theta| max %.5f rad", r.theta_max);
    CHECK(r.remaining > r.remaining0 - 0.01, "nothing poured: %.3f of %.3f", r.remaining, r.remaining0);
    std::printf("brake: |theta| max %.2e rad over 1 s, remaining %.3f\n", r.theta_max, r.remaining);
  }
  {  // The positive torque against the engaged brake (40 N m, twice the drive's peak): still held.
    const Run r = run(0.12, 1.0, true, 1u);
    CHECK(r.ok, "the world ran");
    CHECK(r.theta_max < 1.0 * kPi / 180.0, "held against the motor: |theta| max %.5f rad", r.theta_max);
    std::printf("brake against the torque: |theta| max %.2e rad over 1 s\n", r.theta_max);
  }
  {  // The same seed repeats exactly; another differs.
    const Run a = run(0.12, 0.5, false, 7u), b = run(0.12, 0.5, false, 7u), c = run(0.12, 0.5, false, 8u);
    CHECK(a.hash == b.hash && a.shaft == b.shaft, "seed 7 twice: %016llx / %016llx", static_cast<unsigned long long>(a.hash),
          static_cast<unsigned long long>(b.hash));
    CHECK(a.hash != c.hash, "seed 8 differs from seed 7");
    std::printf("determinism: seed 7 hash %016llx twice, seed 8 %016llx\n", static_cast<unsigned long long>(a.hash),
                static_cast<unsigned long long>(c.hash));
  }
  {  // The gearbox (gear_load_at_motor): the motor pays the loss when it drives, the bucket when it drives back.
    const double drive_nm = vb::gear_load_at_motor(10.0, 1.0, 20.0, 0.9), back_nm = vb::gear_load_at_motor(10.0, -1.0, 20.0, 0.9);
    CHECK(std::fabs(drive_nm - 10.0 / (20.0 * 0.9)) < 1e-12 && std::fabs(back_nm - 10.0 * 0.9 / 20.0) < 1e-12,
          "10 N m at the output: %.4f N m at the motor driving, %.4f driven back", drive_nm, back_nm);
    CHECK(std::fabs(vb::default_gear_efficiency() - 29491.0 / 32768.0) < 1e-12, "host_sim's full drive's 0.90: %.5f",
          vb::default_gear_efficiency());
  }
  {  // The empty rig: the positive torque turns the empty bucket; its Sensors frame reads the angle and empty
     // scales (the load cells' noise only); with the brake engaged it is held.
    for (bool brake : {false, true}) {
      vb::AnalogOptions o;
      Board b(o);
      vb::WorldCouplingOptions wo;
      vb::EmptyBucket empty(wo, b.set.plant.get());
      empty.set_brake(brake);
      Drive drive(b, 0.12);
      double theta_max = 0.0;
      for (int n = 0; n < 10000; ++n) {  // 0.5 s
        drive.step();
        theta_max = std::fmax(theta_max, std::fabs(empty.bucket_theta()));
      }
      pour_can_frame_t f{};
      pour_can_sensors_t m{};
      CHECK(empty.sensors_frame(0u, &f) && pour_can_unpack_sensors(&f, &m) == POUR_CAN_RX_OK, "the empty rig's frame packs");
      CHECK(empty.steps() >= 499u && empty.steps() <= 500u, "lockstep: %u steps in 0.5 s", empty.steps());
      CHECK(std::abs(m.scale_rotating_g) <= 3 && std::abs(m.scale_target_g) <= 3, "empty scales: %d g, %d g", m.scale_rotating_g,
            m.scale_target_g);
      if (brake) {
        CHECK(theta_max < 0.1 * kPi / 180.0, "held by the brake: |theta| max %.2e rad", theta_max);
      } else {
        const double th = empty.bucket_theta();
        CHECK(th > 0.1, "the empty bucket turned: %.3f rad", th);
        CHECK(std::fabs(b.set.plant->theta() / 20.0 - th) < 0.02, "the shaft follows through the gear: %.4f vs %.4f rad",
              b.set.plant->theta() / 20.0, th);
        // the frame is the step's sample (the bucket has moved on since, within one step)
        const double enc = static_cast<double>(m.encoder) * 2.0 * kPi / (1u << poursim_default_config().encoder_bits);
        CHECK(std::fabs(enc - th) < 0.01, "the output encoder reads the angle: %.4f vs %.4f rad", enc, th);
        std::printf("empty rig: theta %.3f rad after 0.5 s, encoder %u, scales %d / %d g\n", th, m.encoder, m.scale_rotating_g,
                    m.scale_target_g);
      }
    }
  }
  {  // Bad options: a one-line error, no world, the plant left without a load.
    const double bad[][2] = {{0.0, 4.4}, {-1.0, 4.4}, {NAN, 4.4}, {2000.0, -1.0}, {2000.0, INFINITY}};
    for (const auto& kd : bad) {
      vb::AnalogOptions o;
      Board b(o);
      vb::WorldCouplingOptions wo;
      wo.stiffness_nm_per_rad = kd[0];
      wo.damping_nms = kd[1];
      vb::WorldCoupling world(wo, b.set.plant.get());
      const std::string& e = world.error();
      CHECK(!world.ok() && !e.empty() && e.find('\n') == std::string::npos &&
                (e.find(kd[0] > 0.0 ? "damping_nms" : "stiffness_nm_per_rad") != std::string::npos),
            "k %g, c %g: error '%s'", kd[0], kd[1], e.c_str());
      b.run_s(2e-3);  // the plant runs on without the world
      CHECK(world.steps() == 0u, "no world stepped");
    }
  }
  if (failures == 0) std::printf("ok\n");
  return failures == 0 ? 0 : 1;
}
