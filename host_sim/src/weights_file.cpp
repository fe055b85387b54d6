// SPDX-License-Identifier: MIT
// weights.h at run time: a small parser for the one layout the exporter writes (docs/weights-h.md),
// strict enough that a truncated, reshaped or corrupted file is refused with the field it breaks.
#include "poursim/weights_file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "poursim_internal.hpp"

using poursim::set_error;

namespace {

constexpr size_t kMaxFileBytes = 1 << 20;

struct Ctx {
  const std::string &text;
  const char *name;
  char *err;
  size_t err_len;
  int line_of(size_t offset) const {
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(std::min(offset, text.size())), '\n'));
  }
};

// Comments become spaces (newlines kept) so offsets and line numbers stay those of the file.
std::string strip_comments(const std::string &in) {
  std::string out = in;
  size_t i = 0;
  while (i < out.size()) {
    if (out.compare(i, 2, "/*") == 0) {
      size_t end = out.find("*/", i + 2);
      size_t stop = end == std::string::npos ? out.size() : end + 2;
      for (size_t k = i; k < stop; ++k)
        if (out[k] != '\n') out[k] = ' ';
      i = stop;
    } else if (out.compare(i, 2, "//") == 0) {
      while (i < out.size() && out[i] != '\n') out[i++] = ' ';
    } else {
      ++i;
    }
  }
  return out;
}

// One element of a brace initializer: a scalar token or a nested list.
struct Node {
  bool is_list = false;
  std::string token;
  size_t offset = 0;
  std::vector<Node> items;
};

// Parses "{ a, b, {c, d}, }" starting at text[pos] == '{'. Returns false at end of text (truncated).
bool parse_braces(const std::string &t, size_t &pos, Node &node, std::string &problem) {
  node.is_list = true;
  node.offset = pos;
  ++pos; // '{'
  for (;;) {
    while (pos < t.size() && std::isspace(static_cast<unsigned char>(t[pos]))) ++pos;
    if (pos >= t.size()) {
      problem = "ends before its closing '}' (truncated)";
      return false;
    }
    if (t[pos] == '}') {
      ++pos;
      return true;
    }
    Node item;
    if (t[pos] == '{') {
      if (!parse_braces(t, pos, item, problem)) return false;
    } else {
      item.offset = pos;
      while (pos < t.size() && t[pos] != ',' && t[pos] != '}' && t[pos] != '{' && t[pos] != ';') item.token += t[pos++];
      if (pos >= t.size() || t[pos] == ';' || t[pos] == '{') {
        problem = "ends before its closing '}' (truncated)";
        return false;
      }
      while (!item.token.empty() && std::isspace(static_cast<unsigned char>(item.token.back()))) item.token.pop_back();
      if (item.token.empty()) {
        problem = "has an empty element";
        return false;
      }
    }
    node.items.push_back(item);
    while (pos < t.size() && std::isspace(static_cast<unsigned char>(t[pos]))) ++pos;
    if (pos < t.size() && t[pos] == ',') ++pos;
  }
}

bool parse_int(const std::string &tok, long long &v) {
  std::string s = tok;
  while (!s.empty() && (s.back() == 'u' || s.back() == 'U' || s.back() == 'l' || s.back() == 'L')) s.pop_back();
  if (s.empty()) return false;
  errno = 0;
  char *end = nullptr;
  v = std::strtoll(s.c_str(), &end, 0);
  return errno == 0 && end != s.c_str() && *end == '\0';
}

bool parse_float(const std::string &tok, double &v) {
  std::string s = tok;
  if (!s.empty() && (s.back() == 'f' || s.back() == 'F')) s.pop_back();
  if (s.empty()) return false;
  errno = 0;
  char *end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && std::isfinite(v);
}

// Finds "<name>[d0][d1] = {...};" (or "[d0]") and returns its rows of tokens.
int read_array(const Ctx &c, const std::string &t, const char *type, const char *name, int rows, int cols,
               const std::map<std::string, long long> &macros, std::vector<Node> &values, bool required,
               bool *found) {
  std::regex decl(std::string("(\\w+)\\s+") + name + "\\s*((\\[[^\\]]*\\]\\s*)+)=");
  std::smatch m;
  *found = false;
  if (!std::regex_search(t, m, decl)) {
    if (!required) return POURSIM_OK;
    return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s: %s is missing", c.name, name);
  }
  *found = true;
  size_t at = static_cast<size_t>(m.position(0));
  int line = c.line_of(at);
  // Declared dimensions must agree with the macros (a number or the macro's name).
  if (m[1].str() != type)
    return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s is declared %s, expected %s", c.name, line, name,
                     m[1].str().c_str(), type);
  std::string dims = m[2].str();
  std::regex dim_re("\\[\\s*([^\\]\\s]*)\\s*\\]");
  std::vector<long long> declared;
  for (auto it = std::sregex_iterator(dims.begin(), dims.end(), dim_re); it != std::sregex_iterator(); ++it) {
    std::string d = (*it)[1].str();
    long long v = -1;
    auto mac = macros.find(d);
    if (mac != macros.end())
      v = mac->second;
    else if (!d.empty() && !parse_int(d, v))
      return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s has an unknown dimension '%s'", c.name, line,
                       name, d.c_str());
    declared.push_back(v);
  }
  std::vector<long long> want = rows > 0 ? std::vector<long long>{rows, cols} : std::vector<long long>{cols};
  if (declared.size() != want.size())
    return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s has %zu dimensions, expected %zu", c.name, line,
                     name, declared.size(), want.size());
  for (size_t k = 0; k < want.size(); ++k)
    if (declared[k] != -1 && declared[k] != want[k])
      return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s dimension %zu is %lld, expected %lld", c.name,
                       line, name, k, declared[k], want[k]);
  size_t pos = at + static_cast<size_t>(m.length(0));
  while (pos < t.size() && std::isspace(static_cast<unsigned char>(t[pos]))) ++pos;
  if (pos >= t.size() || t[pos] != '{')
    return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s: expected '{' after '='", c.name, line, name);
  Node root;
  std::string problem;
  if (!parse_braces(t, pos, root, problem))
    return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s %s", c.name, line, name, problem.c_str());
  while (pos < t.size() && std::isspace(static_cast<unsigned char>(t[pos]))) ++pos;
  if (pos >= t.size() || t[pos] != ';')
    return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s: expected ';' after its initializer (truncated?)",
                     c.name, line, name);
  values.clear();
  if (rows > 0) {
    if (root.items.size() != static_cast<size_t>(rows))
      return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s has %zu rows, expected %d", c.name, line, name,
                       root.items.size(), rows);
    for (size_t r = 0; r < root.items.size(); ++r) {
      const Node &row = root.items[r];
      if (!row.is_list || row.items.size() != static_cast<size_t>(cols))
        return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s row %zu has %zu values, expected %d", c.name,
                         c.line_of(row.offset), name, r, row.is_list ? row.items.size() : 1, cols);
      for (const Node &v : row.items) {
        if (v.is_list)
          return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s row %zu nests too deep", c.name,
                           c.line_of(v.offset), name, r);
        values.push_back(v);
      }
    }
  } else {
    if (root.items.size() != static_cast<size_t>(cols))
      return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s has %zu values, expected %d", c.name, line, name,
                       root.items.size(), cols);
    for (const Node &v : root.items) {
      if (v.is_list)
        return set_error(c.err, c.err_len, POURSIM_EPARSE, "%s:%d: %s nests too deep", c.name, line, name);
      values.push_back(v);
    }
  }
  return POURSIM_OK;
}

struct MacroSpec {
  const char *name;
  long long min, max;
  const char *range;
};

const MacroSpec kMacros[] = {
    {"POUR_WEIGHTS_FORMAT", 1, 1, "only format 1 is supported"},
    {"POUR_WEIGHTS_N_FEATURES", POUR_POLICY_N_FEATURES, POUR_POLICY_N_FEATURES, "must be 6"},
    {"POUR_WEIGHTS_N_ACTIONS", POUR_POLICY_MIN_ACTIONS, POUR_POLICY_MAX_ACTIONS, "must be 2..16"},
    {"POUR_WEIGHTS_W_FRAC_BITS", 0, 15, "must be 0..15"},
    {"POUR_WEIGHTS_DECISION_PERIOD_MS", 1, 65535, "must be 1..65535"},
    {"POUR_WEIGHTS_THETA_MIN_URAD", INT32_MIN, INT32_MAX, "must fit int32"},
    {"POUR_WEIGHTS_THETA_MAX_URAD", INT32_MIN, INT32_MAX, "must fit int32"},
    {"POUR_WEIGHTS_OMEGA_MAX_URAD_S", 1, INT32_MAX, "must be > 0"},
    {"POUR_WEIGHTS_TAU_MAX_MNM", 1, INT32_MAX, "must be > 0"},
    {"POUR_WEIGHTS_CONTENT_HASH", 0, UINT32_MAX, "must fit uint32"},
};

} // namespace

extern "C" int poursim_weights_parse(const char *text, size_t len, const char *name, poursim_weights_file_t *out,
                                     char *err, size_t err_len) {
  if (text == nullptr || out == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "weights: NULL argument");
  if (name == nullptr) name = "weights.h";
  const std::string raw(text, len);
  if (raw.find('\0') != std::string::npos)
    return set_error(err, err_len, POURSIM_EPARSE, "%s: contains NUL bytes (not a text file)", name);
  const std::string t = strip_comments(raw);
  Ctx c{t, name, err, err_len};
  std::memset(out, 0, sizeof *out);

  // Macros: one #define per line.
  std::map<std::string, long long> macros;
  std::map<std::string, int> macro_line;
  std::regex def_re("^[ \\t]*#[ \\t]*define[ \\t]+(POUR_WEIGHTS_[A-Z0-9_]+)[ \\t]*(.*)$");
  size_t line_start = 0;
  for (int line = 1; line_start < t.size(); ++line) {
    size_t line_end = t.find('\n', line_start);
    if (line_end == std::string::npos) line_end = t.size();
    const std::string text_line = t.substr(line_start, line_end - line_start);
    line_start = line_end + 1;
    std::smatch dm;
    if (!std::regex_match(text_line, dm, def_re)) continue;
    std::string key = dm[1].str(), value = dm[2].str();
    while (!value.empty() && std::isspace(static_cast<unsigned char>(value.back()))) value.pop_back();
    if (key == "POUR_WEIGHTS_H") continue; // include guard
    bool known = false;
    for (const MacroSpec &s : kMacros) known = known || key == s.name;
    if (!known) continue; // other macros are allowed and ignored
    if (macros.count(key))
      return set_error(err, err_len, POURSIM_EPARSE, "%s:%d: %s is defined twice", name, line, key.c_str());
    long long v = 0;
    if (value.empty() || !parse_int(value, v))
      return set_error(err, err_len, POURSIM_EPARSE, "%s:%d: %s: '%s' is not an integer", name, line, key.c_str(),
                       value.c_str());
    macros[key] = v;
    macro_line[key] = line;
  }
  for (const MacroSpec &s : kMacros) {
    auto m = macros.find(s.name);
    if (m == macros.end()) return set_error(err, err_len, POURSIM_EPARSE, "%s: %s is missing", name, s.name);
    if (m->second < s.min || m->second > s.max)
      return set_error(err, err_len, POURSIM_EINVAL, "%s:%d: %s = %lld: %s", name, macro_line[s.name], s.name,
                       m->second, s.range);
  }
  out->format = static_cast<int32_t>(macros["POUR_WEIGHTS_FORMAT"]);
  out->n_features = static_cast<int32_t>(macros["POUR_WEIGHTS_N_FEATURES"]);
  out->n_actions = static_cast<int32_t>(macros["POUR_WEIGHTS_N_ACTIONS"]);
  out->w_frac_bits = static_cast<int32_t>(macros["POUR_WEIGHTS_W_FRAC_BITS"]);
  out->decision_period_ms = static_cast<int32_t>(macros["POUR_WEIGHTS_DECISION_PERIOD_MS"]);
  out->theta_min_urad = static_cast<int32_t>(macros["POUR_WEIGHTS_THETA_MIN_URAD"]);
  out->theta_max_urad = static_cast<int32_t>(macros["POUR_WEIGHTS_THETA_MAX_URAD"]);
  out->omega_max_urad_s = static_cast<int32_t>(macros["POUR_WEIGHTS_OMEGA_MAX_URAD_S"]);
  out->tau_max_mnm = static_cast<int32_t>(macros["POUR_WEIGHTS_TAU_MAX_MNM"]);
  out->content_hash = static_cast<uint32_t>(macros["POUR_WEIGHTS_CONTENT_HASH"]);
  if (out->theta_max_urad <= out->theta_min_urad)
    return set_error(err, err_len, POURSIM_EINVAL, "%s:%d: POUR_WEIGHTS_THETA_MAX_URAD = %d must be > THETA_MIN_URAD = %d",
                     name, macro_line["POUR_WEIGHTS_THETA_MAX_URAD"], out->theta_max_urad, out->theta_min_urad);
  const int n = out->n_actions, nf = POUR_POLICY_N_FEATURES;

  std::vector<Node> vals;
  bool found = false;
  int rc = read_array(c, t, "int16_t", "pour_weights_w", nf, n, macros, vals, true, &found);
  if (rc != POURSIM_OK) return rc;
  for (size_t i = 0; i < vals.size(); ++i) {
    long long v;
    if (!parse_int(vals[i].token, v) || v < INT16_MIN || v > INT16_MAX)
      return set_error(err, err_len, POURSIM_EINVAL, "%s:%d: pour_weights_w[%zu][%zu] = '%s' is not an int16", name,
                       c.line_of(vals[i].offset), i / static_cast<size_t>(n), i % static_cast<size_t>(n),
                       vals[i].token.c_str());
    out->w[i] = static_cast<int16_t>(v);
  }
  rc = read_array(c, t, "int16_t", "pour_weights_action_levels_q15", 0, n, macros, vals, true, &found);
  if (rc != POURSIM_OK) return rc;
  for (size_t i = 0; i < vals.size(); ++i) {
    long long v;
    if (!parse_int(vals[i].token, v) || v < INT16_MIN || v > INT16_MAX)
      return set_error(err, err_len, POURSIM_EINVAL, "%s:%d: pour_weights_action_levels_q15[%zu] = '%s' is not a Q15 int16",
                       name, c.line_of(vals[i].offset), i, vals[i].token.c_str());
    out->levels[i] = static_cast<q15_t>(v);
    if (i > 0 && out->levels[i] <= out->levels[i - 1])
      return set_error(err, err_len, POURSIM_EINVAL,
                       "%s:%d: pour_weights_action_levels_q15 must be strictly increasing (index %zu)", name,
                       c.line_of(vals[i].offset), i);
  }
  rc = read_array(c, t, "float", "pour_weights_w_float", nf, n, macros, vals, false, &found);
  if (rc != POURSIM_OK) return rc;
  out->has_float_reference = found ? 1 : 0;
  for (size_t i = 0; found && i < vals.size(); ++i) {
    double v;
    if (!parse_float(vals[i].token, v) || std::fabs(v) > 3.4e38)
      return set_error(err, err_len, POURSIM_EINVAL, "%s:%d: pour_weights_w_float[%zu][%zu] = '%s' is not a finite float",
                       name, c.line_of(vals[i].offset), i / static_cast<size_t>(n), i % static_cast<size_t>(n),
                       vals[i].token.c_str());
    out->w_float[i] = static_cast<float>(v);
  }

  pour_policy_weights_t view;
  poursim_weights_view(out, &view);
  uint32_t h = pour_policy_weights_hash(&view);
  if (h != out->content_hash)
    return set_error(err, err_len, POURSIM_EINVAL,
                     "%s:%d: POUR_WEIGHTS_CONTENT_HASH is 0x%08x but the content hashes to 0x%08x (edited or corrupted)",
                     name, macro_line["POUR_WEIGHTS_CONTENT_HASH"], out->content_hash, h);
  pour_status_t st = pour_policy_weights_validate(&view);
  if (st != POUR_OK)
    return set_error(err, err_len, POURSIM_EINVAL, "%s: the firmware core refuses these weights: %s", name,
                     pour_status_name(st));
  return POURSIM_OK;
}

extern "C" int poursim_weights_load(const char *path, poursim_weights_file_t *out, char *err, size_t err_len) {
  if (path == nullptr || out == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "weights: NULL argument");
  std::ifstream in(path, std::ios::binary);
  if (!in) return set_error(err, err_len, POURSIM_EIO, "cannot read weights file '%s': %s", path, std::strerror(errno));
  std::string text;
  char buf[4096];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxFileBytes)
      return set_error(err, err_len, POURSIM_EPARSE, "%s: larger than %zu bytes, not a weights.h", path, kMaxFileBytes);
  }
  if (in.bad()) return set_error(err, err_len, POURSIM_EIO, "error reading weights file '%s'", path);
  return poursim_weights_parse(text.data(), text.size(), path, out, err, err_len);
}

extern "C" void poursim_weights_view(const poursim_weights_file_t *f, pour_policy_weights_t *v) {
  std::memset(v, 0, sizeof *v);
  v->n_actions = static_cast<uint8_t>(f->n_actions);
  v->w_frac_bits = static_cast<uint8_t>(f->w_frac_bits);
  v->decision_period_ms = static_cast<uint16_t>(f->decision_period_ms);
  v->w = f->w;
  v->action_levels = f->levels;
  v->norm.theta_min_urad = f->theta_min_urad;
  v->norm.theta_max_urad = f->theta_max_urad;
  v->norm.omega_max_urad_s = f->omega_max_urad_s;
  v->tau_max_mnm = f->tau_max_mnm;
  v->content_hash = f->content_hash;
}

extern "C" void poursim_weights_float_policy(const poursim_weights_file_t *f, double *w_out, double *levels_out,
                                             poursim_policy_t *p) {
  const int n = f->n_actions;
  const double scale = std::ldexp(1.0, -f->w_frac_bits);
  for (int i = 0; i < POUR_POLICY_N_FEATURES * n; ++i) w_out[i] = f->w[i] * scale;
  for (int i = 0; i < n; ++i) levels_out[i] = f->levels[i] / 32768.0;
  std::memset(p, 0, sizeof *p);
  p->n_actions = n;
  p->decision_period = f->decision_period_ms;
  p->w = w_out;
  p->levels = levels_out;
  p->theta_min = f->theta_min_urad * 1e-6;
  p->theta_max = f->theta_max_urad * 1e-6;
  p->omega_max = f->omega_max_urad_s * 1e-6;
  p->greedy = 1;
}
