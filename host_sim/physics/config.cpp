// SPDX-License-Identifier: MIT
// The simulator's configuration: config_fields.h as a table of fields (defaults, ranges, units), file I/O.
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
#include <new>
#include <sstream>
#include <string>

#include "poursim/poursim.h"
#include "poursim_internal.hpp"

namespace {

enum class Kind { DOUBLE, INT, U32 };

struct Field {
  const char *name;
  size_t offset;
  Kind kind;
  double def, min, max; // default; inclusive range
  const char *unit, *doc;
};

#define POURSIM_FIELD(kind, name, d, lo, hi, unit, doc) {#name, offsetof(poursim_config_t, name), Kind::kind, d, lo, hi, unit, doc},
#define POURSIM_NO_SECTION(title)
const Field kFields[] = {POURSIM_CONFIG_FIELDS(POURSIM_FIELD, POURSIM_NO_SECTION)};
#undef POURSIM_FIELD

const Field *find_field(const char *name) {
  for (const Field &f : kFields) {
    if (std::strcmp(f.name, name) == 0) return &f;
  }
  return nullptr;
}

double get_value(const poursim_config_t *c, const Field &f) {
  const char *base = reinterpret_cast<const char *>(c) + f.offset;
  switch (f.kind) {
    case Kind::DOUBLE: return *reinterpret_cast<const double *>(base);
    case Kind::INT: return *reinterpret_cast<const int *>(base);
    case Kind::U32: return *reinterpret_cast<const uint32_t *>(base);
  }
  return 0.0;
}

// Stores v, which the caller has checked against the field's range (and, for integers, to be whole).
void put_value(poursim_config_t *c, const Field &f, double v) {
  char *base = reinterpret_cast<char *>(c) + f.offset;
  switch (f.kind) {
    case Kind::DOUBLE: *reinterpret_cast<double *>(base) = v; break;
    case Kind::INT: *reinterpret_cast<int *>(base) = static_cast<int>(v); break;
    case Kind::U32: *reinterpret_cast<uint32_t *>(base) = static_cast<uint32_t>(v); break;
  }
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
  for (const Field &f : kFields) put_value(&c, f, f.def);
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
  if (f->kind != Kind::DOUBLE && v != std::floor(v))
    return set_error(err, err_len, POURSIM_EPARSE, "config %s: '%s' is not an integer", key, value);
  put_value(c, *f, v);
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
                          f.max, f.kind == Kind::DOUBLE ? "" : " (integer)", get_value(&d, f));
    if (n < 0 || static_cast<size_t>(n) >= len - used) return POURSIM_EINVAL;
    used += static_cast<size_t>(n);
  }
  return POURSIM_OK;
}

namespace {

// The shortest text that reads back as the same double (integers as integers).
std::string format_value(const Field &f, double v) {
  char buf[40];
  if (f.kind != Kind::DOUBLE || (v == std::floor(v) && std::fabs(v) < 1e15)) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

uint64_t fnv1a64(const std::string &text) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (char ch : text) h = (h ^ static_cast<unsigned char>(ch)) * 0x100000001b3ULL;
  return h;
}

// Every key in config_fields.h order under its section's heading, each with its unit and meaning.
std::string config_text(const poursim_config_t *c) {
  std::ostringstream body;
  size_t i = 0;
  auto field = [&](const Field &f) {
    const std::string line = std::string(f.name) + " = " + format_value(f, get_value(c, f));
    body << line << std::string(line.size() < 32 ? 32 - line.size() : 1, ' ') << "# [" << f.unit << "] " << f.doc
         << "\n";
  };
#define POURSIM_WRITE_FIELD(kind, name, d, lo, hi, unit, doc) field(kFields[i++]);
#define POURSIM_WRITE_SECTION(title) body << "\n# " << title << "\n";
  POURSIM_CONFIG_FIELDS(POURSIM_WRITE_FIELD, POURSIM_WRITE_SECTION)
#undef POURSIM_WRITE_FIELD
#undef POURSIM_WRITE_SECTION
  char banner[512];
  std::snprintf(banner, sizeof banner,
                "# poursim config, every key. Generated by poursim_config_write from the key list in\n"
                "# host_sim/include/poursim/config_fields.h (body fnv1a64 %016llx): do not edit. From the defaults\n"
                "# it is configs/sim/default.cfg: cmake --build --preset host --target default_cfg\n"
                "# Format: one \"key = value\" per line, '#' starts a comment; units SI (m, kg, s, rad, N m).\n"
                "# Load with host_sim --config FILE or pour.sim.poursim.make_config(path=FILE).\n",
                static_cast<unsigned long long>(fnv1a64(body.str())));
  return banner + body.str();
}

} // namespace

// Written beside path and renamed over it, so that a failed write leaves the old file whole.
extern "C" int poursim_config_write(const poursim_config_t *c, const char *path, char *err, size_t err_len) {
  if (c == nullptr || path == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "config_write: NULL argument");
  const std::string tmp = std::string(path) + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) return set_error(err, err_len, POURSIM_EIO, "cannot write config file '%s'", path);
    out << config_text(c);
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      return set_error(err, err_len, POURSIM_EIO, "error writing '%s'", path);
    }
  }
  if (std::rename(tmp.c_str(), path) != 0) {
    std::remove(tmp.c_str());
    return set_error(err, err_len, POURSIM_EIO, "cannot rename '%s' to '%s': %s", tmp.c_str(), path,
                     std::strerror(errno));
  }
  return POURSIM_OK;
}

extern "C" poursim_config_t *poursim_config_new(const poursim_config_t *src) {
  auto *c = new (std::nothrow) poursim_config_t;
  if (c != nullptr) *c = src != nullptr ? *src : poursim_default_config();
  return c;
}

extern "C" void poursim_config_free(poursim_config_t *c) { delete c; }

extern "C" int poursim_config_get(const poursim_config_t *c, const char *key, double *value, char *err,
                                  size_t err_len) {
  if (c == nullptr || key == nullptr || value == nullptr)
    return set_error(err, err_len, POURSIM_EINVAL, "config_get: NULL argument");
  const Field *f = find_field(key);
  if (f == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "unknown config key '%s'", key);
  *value = get_value(c, *f);
  return POURSIM_OK;
}

extern "C" const char *poursim_config_key(int index) {
  const int n = static_cast<int>(sizeof kFields / sizeof kFields[0]);
  return index >= 0 && index < n ? kFields[index].name : nullptr;
}

extern "C" int poursim_config_key_info(const char *key, int *integer, double *min, double *max, double *def,
                                       const char **unit, const char **doc) {
  const Field *f = key != nullptr ? find_field(key) : nullptr;
  if (f == nullptr) return POURSIM_EINVAL;
  if (integer != nullptr) *integer = f->kind == Kind::DOUBLE ? 0 : 1;
  if (min != nullptr) *min = f->min;
  if (max != nullptr) *max = f->max;
  if (def != nullptr) *def = f->def;
  if (unit != nullptr) *unit = f->unit;
  if (doc != nullptr) *doc = f->doc;
  return POURSIM_OK;
}
