// SPDX-License-Identifier: MIT
// The simulator's configuration: defaults, one table of fields (name, range), file I/O.
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "poursim/poursim.h"
#include "poursim_internal.hpp"

namespace {

enum class Kind { Double, Int, U32 };

struct Field {
  const char *name;
  size_t offset;
  Kind kind;
  double min, max; // inclusive range
  const char *unit;
};

#define F(name, kind, lo, hi, unit) {#name, offsetof(poursim_config_t, name), Kind::kind, lo, hi, unit}
// Ranges: wide enough for experiments, narrow enough that the physics stays meaningful.
const Field kFields[] = {
    F(dt, Double, 1e-4, 0.01, "s"),
    F(substeps, Int, 1, 16, "-"),
    F(episode_s, Double, 0.01, 600.0, "s"),
    F(settle_s, Double, 0.0, 10.0, "s"),
    F(bucket_inner_width, Double, 0.05, 1.0, "m"),
    F(bucket_height, Double, 0.05, 1.0, "m"),
    F(bucket_wall, Double, 0.001, 0.05, "m"),
    F(pivot_height, Double, 0.1, 5.0, "m"),
    F(target_dx, Double, -2.0, 2.0, "m"),
    F(bucket_mass, Double, 0.01, 100.0, "kg"),
    F(fill_depth, Double, 0.01, 1.0, "m"),
    F(liquid_density, Double, 500.0, 2000.0, "kg/m^3"),
    F(n_particles, Int, 2, POURSIM_MAX_PARTICLES, "-"),
    F(fluid, Int, 0, 1, "0/1"),
    F(fluid_smoothing, Double, 1.2, 3.0, "-"),
    F(fluid_contact_radius, Double, 0.1, 0.5, "-"),
    F(fluid_stiffness, Double, 10.0, 1e5, "m/s^2"),
    F(fluid_viscosity, Double, 0.0, 1e3, "1/s"),
    F(fluid_agitation, Double, 0.0, 5.0, "m/s"),
    F(restitution_liquid, Double, 0.0, 1.0, "-"),
    F(restitution_wall, Double, 0.0, 1.0, "-"),
    F(friction, Double, 0.0, 2.0, "-"),
    F(restitution_threshold, Double, 0.0, 100.0, "m/s"),
    F(contact_hertz, Double, 1.0, 10000.0, "Hz"),
    F(tau_max, Double, 0.01, 1000.0, "N m"),
    F(theta_min, Double, -1.0, 0.0, "rad"),
    F(theta_max, Double, 0.1, 3.1, "rad"),
    F(brake_torque, Double, 0.0, 1000.0, "N m"),
    F(motor_peak_torque, Double, 0.1, 1000.0, "N m at the output"),
    F(motor_no_load_speed, Double, 0.1, 1000.0, "rad/s at the output"),
    F(motor_rotor_inertia, Double, 0.0, 0.1, "kg m^2 at the motor"),
    F(gear_ratio, Double, 1.0, 1000.0, "-"),
    F(friction_coulomb, Double, 0.0, 100.0, "N m"),
    F(friction_viscous, Double, 0.0, 100.0, "N m s/rad"),
    F(command_latency_ticks, Int, 1, 100, "steps"),
    F(drive, Int, 0, 1, "0 ideal / 1 foc"),
    F(drive_regen, Int, 0, 1, "0/1"),
    F(drive_fault, Int, 0, 4, "0 none, 1 open, 2 short, 3 encoder, 4 offset"),
    F(supply_voltage, Double, 12.0, 26.0, "V"),
    F(bus_capacitance, Double, 1e-5, 0.1, "F"),
    F(encoder_bits, Int, 8, 24, "bits"),
    F(scale_rate_hz, Double, 1.0, 10000.0, "Hz"),
    F(scale_delay_s, Double, 0.0, 1.0, "s"),
    F(scale_noise_g, Double, 0.0, 1000.0, "g"),
    F(scale_resolution_g, Double, 1.0, 1000.0, "g"),
    F(rand_fill, Double, 0.0, 0.5, "relative"),
    F(rand_target_dx, Double, 0.0, 0.1, "m"),
    F(rand_pivot_height, Double, 0.0, 0.1, "m"),
    F(rand_motor, Double, 0.0, 0.5, "relative"),
    F(rand_bucket_mass, Double, 0.0, 0.5, "relative"),
    F(rand_liquid, Double, 0.0, 0.5, "relative"),
    F(rand_sensor, Double, 0.0, 0.9, "relative"),
    F(obs_theta_min, Double, -3.2, 3.2, "rad"),
    F(obs_theta_max, Double, -3.2, 3.2, "rad"),
    F(obs_omega_max, Double, 1e-3, 1000.0, "rad/s"),
    F(k_target, Double, 0.0, 1e6, "-"),
    F(k_spill, Double, 0.0, 1e6, "-"),
    F(gamma, Double, 0.0, 1.0, "-"),
    F(seed, U32, 0, 4294967295.0, "-"),
};
#undef F

const Field *find_field(const char *name) {
  for (const Field &f : kFields) {
    if (std::strcmp(f.name, name) == 0) return &f;
  }
  return nullptr;
}

double get_value(const poursim_config_t *c, const Field &f) {
  const char *base = reinterpret_cast<const char *>(c) + f.offset;
  switch (f.kind) {
    case Kind::Double: return *reinterpret_cast<const double *>(base);
    case Kind::Int: return *reinterpret_cast<const int *>(base);
    case Kind::U32: return *reinterpret_cast<const uint32_t *>(base);
  }
  return 0.0;
}

std::string trim(const std::string &s) {
  size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

} // namespace

namespace poursim {

int set_error(char *err, size_t err_len, int status, const char *fmt, ...) {
  if (err != nullptr && err_len > 0) {
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(err, err_len, fmt, ap);
    va_end(ap);
  }
  return status;
}

} // namespace poursim

using poursim::set_error;

extern "C" poursim_config_t poursim_default_config(void) {
  poursim_config_t c;
  std::memset(&c, 0, sizeof c);
  c.dt = 0.001;
  c.substeps = 1; // with the fluid, only circle-wall contacts: 1 sub-step keeps them within 0.3 mm
  c.episode_s = 10.0;
  c.settle_s = 0.6;
  c.bucket_inner_width = 0.24;
  c.bucket_height = 0.33;
  c.bucket_wall = 0.005;
  c.pivot_height = 0.56;
  c.target_dx = 0.28; // under the stream of a slow pour (docs/simulator.md)
  c.bucket_mass = 2.0;
  c.fill_depth = 0.221;      // 10 L in a round bucket of 24 cm inner diameter
  c.liquid_density = 1030.0; // soymilk
  c.n_particles = 150;
  c.fluid = 1;
  c.fluid_smoothing = 1.8;
  c.fluid_contact_radius = 0.5;
  c.fluid_stiffness = 10000.0;
  c.fluid_viscosity = 5.0;
  c.fluid_agitation = 0.6;
  c.restitution_liquid = 0.5;
  c.restitution_wall = 0.1;
  c.friction = 0.03; // low: the pile levels closer to a liquid (onset 60° vs 65° at 0.1)
  c.restitution_threshold = 1.0;
  c.contact_hertz = 240.0;
  c.tau_max = 20.0;
  c.theta_min = -0.0872664626; // -5°
  c.theta_max = 2.35619449;    // 135°
  c.brake_torque = 40.0;       // twice the drive's peak: holds the full bucket at any tilt (~15 N·m worst)
  // A 48 V BLDC of the 57 mm (NEMA 23) class on a 2-stage 1:20 planetary gearhead; docs/simulator.md
  // ("The rig") derives each number.
  c.motor_peak_torque = 25.0;       // 1.35 N·m peak at the motor × 20 × 0.93 gearhead efficiency
  c.motor_no_load_speed = 21.0;     // 4,000 rpm at 48 V / 20
  c.motor_rotor_inertia = 2.4e-5;   // 240 g·cm² (a 57 mm rotor); × 20² = 0.0096 kg·m² at the output
  c.gear_ratio = 20.0;
  c.friction_coulomb = 0.6;         // the no-load loss split into Coulomb and viscous parts
  c.friction_viscous = 0.02;        // 0.4 N·m at the no-load speed
  c.command_latency_ticks = 1;      // one CAN frame: the torque of tick k acts in tick k + 1
  c.drive = 0;                      // the torque–speed line: the fast default for training
  c.drive_regen = 1;
  c.drive_fault = 0;
  c.supply_voltage = 24.0;          // docs/motor.md: a 24 V bench supply on the B-G431B-ESC1
  c.bus_capacitance = 200e-6;       // docs/motor.md
  c.encoder_bits = 17;
  c.scale_rate_hz = 80.0;           // HX711 with RATE high: 80 samples/s
  c.scale_delay_s = 0.05;           // HX711 output settling time at 80 samples/s: the filter's span
  c.scale_noise_g = 0.5;
  c.scale_resolution_g = 1.0;       // whole grams on the wire
  c.obs_theta_min = 0.0;
  c.obs_theta_max = 2.356194;
  c.obs_omega_max = 4.0;
  c.k_target = 1.0;
  c.k_spill = 5.0;
  c.gamma = 0.9995;
  c.seed = 1;
  return c;
}

extern "C" int poursim_config_validate(const poursim_config_t *c, char *err, size_t err_len) {
  if (c == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "config is NULL");
  for (const Field &f : kFields) {
    double v = get_value(c, f);
    if (!std::isfinite(v) || v < f.min || v > f.max) {
      return set_error(err, err_len, POURSIM_EINVAL, "config %s = %g is out of range [%g, %g] (unit: %s)", f.name,
                       v, f.min, f.max, f.unit);
    }
  }
  const double inner_depth = c->bucket_height - c->bucket_wall;
  if (c->fill_depth > 0.95 * inner_depth)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "config fill_depth %g m overflows the bucket (inner depth %g m; at most 95 %% of it)",
                     c->fill_depth, inner_depth);
  // At least two particles across the bottom, and a lattice that fits the bucket's width.
  const double spacing = poursim::particle_spacing(c);
  if (spacing < 0.003)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "config n_particles %d: too many for fill_depth %g m (spacing %.4f m < 3 mm: contacts would tunnel)",
                     c->n_particles, c->fill_depth, spacing);
  if (2.0 * spacing > c->bucket_inner_width)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "config n_particles %d: too few for fill_depth %g m (spacing %.3f m > half the bucket width)",
                     c->n_particles, c->fill_depth, spacing);
  if (c->obs_theta_max <= c->obs_theta_min)
    return set_error(err, err_len, POURSIM_EINVAL, "config obs_theta_max must be > obs_theta_min");
  if (c->bucket_height <= 2.0 * c->bucket_wall)
    return set_error(err, err_len, POURSIM_EINVAL, "config bucket_height must exceed twice bucket_wall");
  if (c->scale_rate_hz * c->dt > 1.0 + 1e-9)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "config scale_rate_hz %g Hz: faster than the step (at most 1/dt = %g Hz)", c->scale_rate_hz,
                     1.0 / c->dt);
  // The rotating bucket must swing clear of the ground.
  double hw = 0.5 * c->bucket_inner_width + c->bucket_wall, hh = 0.5 * c->bucket_height;
  double sweep = std::sqrt(hw * hw + hh * hh);
  if (c->pivot_height < sweep + 0.01)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "config pivot_height %g: the rotating bucket (corner radius %.3f m) would hit the ground",
                     c->pivot_height, sweep);
  // ... and of the target bucket (the target's top corners must lie outside the swept circle).
  double tx0 = c->target_dx - hw, tx1 = c->target_dx + hw, ty = c->bucket_height - c->pivot_height;
  double nx = std::fmax(tx0, std::fmin(0.0, tx1)); // nearest x of the target's top edge to the pivot
  if (ty > -sweep && std::sqrt(nx * nx + ty * ty) < sweep + 0.005)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "config target_dx %g / pivot_height %g: the rotating bucket would hit the target bucket",
                     c->target_dx, c->pivot_height);
  return POURSIM_OK;
}

namespace poursim {

poursim_config_t draw_episode_config(const poursim_config_t &c, uint32_t seed) {
  if (c.rand_fill == 0 && c.rand_target_dx == 0 && c.rand_pivot_height == 0 && c.rand_motor == 0 &&
      c.rand_bucket_mass == 0 && c.rand_liquid == 0 && c.rand_sensor == 0)
    return c;
  // Its own stream: the liquid's arrangement and agitation of a seed stay what they are without it.
  Rng rng(0xD0A1D0A1ULL ^ (static_cast<unsigned long long>(seed) << 24));
  constexpr int kAttempts = 64;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    // Every draw is taken whichever keys are on, so that turning one key on leaves the others' draws.
    double d[16];
    for (double &x : d) x = 2.0 * rng.uniform() - 1.0; // [-1, 1)
    poursim_config_t e = c;
    e.fill_depth *= 1.0 + c.rand_fill * d[0];
    e.target_dx += c.rand_target_dx * d[1];
    e.pivot_height += c.rand_pivot_height * d[2];
    e.motor_peak_torque *= 1.0 + c.rand_motor * d[3];
    e.motor_no_load_speed *= 1.0 + c.rand_motor * d[4];
    e.friction_coulomb *= 1.0 + c.rand_motor * d[5];
    e.friction_viscous *= 1.0 + c.rand_motor * d[6];
    e.motor_rotor_inertia *= 1.0 + c.rand_motor * d[7];
    e.bucket_mass *= 1.0 + c.rand_bucket_mass * d[8];
    e.fluid_viscosity *= 1.0 + c.rand_liquid * d[9];
    e.fluid_stiffness *= 1.0 + c.rand_liquid * d[10];
    e.fluid_agitation *= 1.0 + c.rand_liquid * d[11];
    e.liquid_density *= 1.0 + c.rand_liquid * d[12];
    e.scale_delay_s *= 1.0 + c.rand_sensor * d[13];
    e.scale_noise_g *= 1.0 + c.rand_sensor * d[14];
    if (c.rand_sensor > 0 && d[15] >= 0.0) e.command_latency_ticks += 1;
    // A draw that makes no valid world (the bucket hits the target, the fill overflows, ...) is drawn
    // again from the same stream; the nominal config if none of kAttempts draws is valid.
    if (poursim_config_validate(&e, nullptr, 0) == POURSIM_OK) return e;
  }
  return c;
}

} // namespace poursim

extern "C" int poursim_config_set(poursim_config_t *c, const char *key, const char *value, char *err,
                                  size_t err_len) {
  if (c == nullptr || key == nullptr || value == nullptr)
    return set_error(err, err_len, POURSIM_EINVAL, "config_set: NULL argument");
  const Field *f = find_field(key);
  if (f == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "unknown config key '%s'", key);
  errno = 0;
  char *end = nullptr;
  double v = std::strtod(value, &end);
  if (end == value || *end != '\0' || errno != 0 || !std::isfinite(v))
    return set_error(err, err_len, POURSIM_EPARSE, "config %s: '%s' is not a number", key, value);
  if (v < f->min || v > f->max)
    return set_error(err, err_len, POURSIM_EINVAL, "config %s = %s is out of range [%g, %g] (unit: %s)", key, value,
                     f->min, f->max, f->unit);
  char *base = reinterpret_cast<char *>(c) + f->offset;
  switch (f->kind) {
    case Kind::Double: *reinterpret_cast<double *>(base) = v; break;
    case Kind::Int:
    case Kind::U32:
      if (v != std::floor(v))
        return set_error(err, err_len, POURSIM_EPARSE, "config %s: '%s' is not an integer", key, value);
      if (f->kind == Kind::Int)
        *reinterpret_cast<int *>(base) = static_cast<int>(v);
      else
        *reinterpret_cast<uint32_t *>(base) = static_cast<uint32_t>(v);
      break;
  }
  return POURSIM_OK;
}

namespace {

constexpr size_t kMaxConfigBytes = 1 << 20; // the same cap as a weights.h; a config is a few KB

// The line of the first key the file set that a validation message names (0 if it names none): the
// range checks and cross-field rules name the keys they are about.
int line_of_named_key(const std::string &msg, const std::map<std::string, int> &lines) {
  for (size_t i = 0; i < msg.size();) {
    size_t j = i;
    while (j < msg.size() && (std::islower(static_cast<unsigned char>(msg[j])) || msg[j] == '_')) ++j;
    if (j > i) {
      auto it = lines.find(msg.substr(i, j - i));
      if (it != lines.end()) return it->second;
      i = j;
    } else {
      ++i;
    }
  }
  return 0;
}

} // namespace

// Same limits as the weights.h loader: bounded size, text only, every key once, every error with the
// file and line it comes from.
extern "C" int poursim_config_load(const char *path, poursim_config_t *c, char *err, size_t err_len) {
  if (path == nullptr || c == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "config_load: NULL argument");
  std::ifstream in(path, std::ios::binary);
  if (!in) return set_error(err, err_len, POURSIM_EIO, "cannot read config file '%s': %s", path, std::strerror(errno));
  std::string text;
  char buf[4096];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxConfigBytes)
      return set_error(err, err_len, POURSIM_EPARSE, "%s: larger than %zu bytes, not a config file", path,
                       kMaxConfigBytes);
  }
  if (in.bad()) return set_error(err, err_len, POURSIM_EIO, "error reading config file '%s'", path);
  std::map<std::string, int> key_line;
  char sub[POURSIM_ERR_LEN];
  int lineno = 0;
  for (size_t start = 0; start < text.size();) {
    size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    std::string line = text.substr(start, stop - start);
    start = stop + 1;
    ++lineno;
    if (line.find('\0') != std::string::npos)
      return set_error(err, err_len, POURSIM_EPARSE, "%s:%d: contains a NUL byte (not a text file)", path, lineno);
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    line = trim(line);
    if (line.empty()) continue;
    size_t eq = line.find('=');
    if (eq == std::string::npos)
      return set_error(err, err_len, POURSIM_EPARSE, "%s:%d: expected 'key = value', got '%.60s'", path, lineno,
                       line.c_str());
    std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
    auto seen = key_line.find(key);
    if (seen != key_line.end())
      return set_error(err, err_len, POURSIM_EPARSE, "%s:%d: %.60s is set twice (first on line %d)", path, lineno,
                       key.c_str(), seen->second);
    int rc = poursim_config_set(c, key.c_str(), value.c_str(), sub, sizeof sub);
    if (rc != POURSIM_OK) return set_error(err, err_len, rc, "%s:%d: %s", path, lineno, sub);
    key_line[key] = lineno;
  }
  int rc = poursim_config_validate(c, sub, sizeof sub);
  if (rc != POURSIM_OK) {
    int line = line_of_named_key(sub, key_line);
    if (line > 0) return set_error(err, err_len, rc, "%s:%d: %s", path, line, sub);
    return set_error(err, err_len, rc, "%s: %s (with the defaults of the keys it does not set)", path, sub);
  }
  return POURSIM_OK;
}

extern "C" int poursim_config_describe(char *buf, size_t len) {
  if (buf == nullptr || len == 0) return POURSIM_EINVAL;
  const poursim_config_t d = poursim_default_config();
  size_t used = 0;
  buf[0] = '\0';
  for (const Field &f : kFields) {
    int n = std::snprintf(buf + used, len - used, "  %-22s [%s] %g..%g%s, default %.6g\n", f.name, f.unit, f.min,
                          f.max, f.kind == Kind::Double ? "" : " (integer)", get_value(&d, f));
    if (n < 0 || static_cast<size_t>(n) >= len - used) return POURSIM_EINVAL;
    used += static_cast<size_t>(n);
  }
  return POURSIM_OK;
}

extern "C" int poursim_config_write(const poursim_config_t *c, const char *path, char *err, size_t err_len) {
  std::ofstream out(path);
  if (!out) return set_error(err, err_len, POURSIM_EIO, "cannot write config file '%s'", path);
  out << "# poursim config (docs/simulator.md describes every key)\n";
  for (const Field &f : kFields) {
    char buf[64];
    double v = get_value(c, f);
    if (f.kind == Kind::Double)
      std::snprintf(buf, sizeof buf, "%.17g", v);
    else
      std::snprintf(buf, sizeof buf, "%.0f", v);
    out << f.name << " = " << buf << "  # [" << f.unit << "]\n";
  }
  return out ? POURSIM_OK : set_error(err, err_len, POURSIM_EIO, "error writing '%s'", path);
}
