// SPDX-License-Identifier: MIT
// weights.h at run time: a tokenizer and a flat parser for the subset of C the exporter writes
// (docs/weights-h.md, "Accepted subset"). Comments, whitespace and CRLF may be added by hand; anything the
// firmware build would refuse is refused here too, naming the file, the line and the field.
// tools/pour/policy/weights_h.py implements the same grammar; tests/data/weights_cases/ holds the cases both
// must agree on.
//
// Worst case: every byte is looked at a bounded number of times (a comment is skipped by one forward scan,
// a number is converted digit by digit and stops at overflow), there is no recursion and no backtracking,
// and what is kept is bounded by the largest policy (6 x 16 values per array). Time is O(n) and memory
// O(1) beyond the input, for n bytes of input. `scripts/bench.sh weights` measures it.
#include "poursim/weights_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "poursim_internal.hpp"

using poursim::set_error;

namespace {

constexpr size_t kMaxFileBytes = 1 << 20;
constexpr int kMaxRows = POUR_POLICY_N_FEATURES;
constexpr int kMaxCols = POUR_POLICY_MAX_ACTIONS;
constexpr size_t kMaxFloatChars = 64; // a %.9g float is at most 16; longer ones are refused, not converted

enum class Tok { End, Newline, Hash, Ident, Number, Punct };

struct Token {
  Tok kind = Tok::End;
  const char *b = nullptr, *e = nullptr;
  int line = 1;
  size_t size() const { return static_cast<size_t>(e - b); }
  bool is(const char *s) const { return size() == std::strlen(s) && std::memcmp(b, s, size()) == 0; }
  bool punct(char c) const { return kind == Tok::Punct && *b == c; }
};

// The token as it may appear in a message: at most 40 characters.
std::string quoted(const Token &t) {
  if (t.kind == Tok::End) return "end of file";
  if (t.kind == Tok::Newline) return "end of line";
  size_t n = static_cast<size_t>(t.e - t.b);
  return "'" + std::string(t.b, n > 40 ? 40 : n) + (n > 40 ? "...'" : "'");
}

struct Parser {
  const char *s, *end;
  const char *name;
  char *err;
  size_t err_len;
  const char *p;
  int line = 1;
  Token tok; // the current token

  int fail(int status, int at_line, const char *fmt, ...) __attribute__((format(printf, 4, 5))) {
    char msg[POURSIM_ERR_LEN];
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (at_line > 0) return set_error(err, err_len, status, "%s:%d: %s", name, at_line, msg);
    return set_error(err, err_len, status, "%s: %s", name, msg);
  }

  // Bytes C and this grammar could read differently: NUL, a CR not before LF (a line end to the compiler,
  // not to us), and a line continuation (backslash or the ??/ trigraph before a newline, which would pull
  // the next line into a // comment).
  int check_bytes() {
    int ln = 1;
    for (const char *q = s; q < end; ++q) {
      if (*q == '\0') return fail(POURSIM_EPARSE, ln, "contains a NUL byte (not a text file)");
      if (*q == '\r' && (q + 1 == end || q[1] != '\n'))
        return fail(POURSIM_EPARSE, ln, "a carriage return not followed by a newline");
      if (*q == '\n') {
        const char *r = q > s && q[-1] == '\r' ? q - 1 : q;
        if ((r > s && r[-1] == '\\') || (r - s >= 3 && std::memcmp(r - 3, "?\?/", 3) == 0))
          return fail(POURSIM_EPARSE, ln, "a line continuation (backslash or ?\?/ before the newline) is not allowed");
        ++ln;
      }
    }
    return POURSIM_OK;
  }

  static bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
  static bool digit(char c) { return c >= '0' && c <= '9'; }

  // Reads the next token into tok. Comments are whitespace; a block comment spanning lines does not end a
  // directive, as in C.
  int next() {
    for (;;) {
      if (p >= end) {
        tok = Token{Tok::End, p, p, line};
        return POURSIM_OK;
      }
      char c = *p;
      if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++p;
      } else if (c == '/' && p + 1 < end && p[1] == '*') {
        int start = line;
        const char *q = p + 2;
        while (q + 1 < end && !(q[0] == '*' && q[1] == '/')) line += *q++ == '\n';
        if (q + 1 >= end) return fail(POURSIM_EPARSE, start, "a comment is not closed (truncated?)");
        p = q + 2;
      } else if (c == '/' && p + 1 < end && p[1] == '/') {
        while (p < end && *p != '\n') ++p;
      } else {
        break;
      }
    }
    const char *b = p;
    char c = *p;
    if (c == '\n') {
      ++p;
      tok = Token{Tok::Newline, b, p, line++};
      return POURSIM_OK;
    }
    Tok kind;
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      while (p < end && ident_char(*p)) ++p;
      kind = Tok::Ident;
    } else if (digit(c) || ((c == '-' || c == '.') && p + 1 < end && (digit(p[1]) || (p[1] == '.' && c == '-')))) {
      // A C preprocessing number (with our sign glued on): digits, letters, '.', and a sign after e/E.
      ++p;
      while (p < end && (ident_char(*p) || *p == '.' ||
                         ((*p == '+' || *p == '-') && (p[-1] == 'e' || p[-1] == 'E'))))
        ++p;
      kind = Tok::Number;
    } else if (std::strchr("#{}[]=,;<>.", c) != nullptr) {
      ++p;
      kind = c == '#' ? Tok::Hash : Tok::Punct;
    } else {
      if (static_cast<unsigned char>(c) >= 0x80)
        return fail(POURSIM_EPARSE, line, "a non-ASCII byte outside a comment");
      return fail(POURSIM_EPARSE, line, "unexpected character '%c'", c);
    }
    tok = Token{kind, b, p, line};
    return POURSIM_OK;
  }
};

// Integer literals: decimal without leading zeros (C reads 010 as octal 8) and without suffixes (-1u is
// not -1 to the compiler); the hash alone may be hex with a 'u'. Returns false if the text is no such
// literal; sets *overflow if it is one whose value does not fit int64.
bool int_literal(const Token &t, bool hash, long long *v, bool *overflow) {
  const char *q = t.b, *e = t.e;
  *overflow = false;
  if (hash && e - q > 1 && (e[-1] == 'u' || e[-1] == 'U')) --e;
  bool neg = !hash && q < e && *q == '-';
  if (neg) ++q;
  int base = 10;
  if (hash && e - q > 2 && q[0] == '0' && (q[1] == 'x' || q[1] == 'X')) {
    base = 16;
    q += 2;
  } else if (e - q > 1 && q[0] == '0') {
    return false;
  }
  if (q == e) return false;
  unsigned long long acc = 0;
  for (; q < e; ++q) {
    int d = Parser::digit(*q) ? *q - '0' : base == 16 && std::isxdigit(static_cast<unsigned char>(*q)) ? (*q | 0x20) - 'a' + 10 : -1;
    if (d < 0) return false;
    if (acc > (0x7fffffffffffffffULL - static_cast<unsigned>(d)) / static_cast<unsigned>(base)) *overflow = true;
    if (!*overflow) acc = acc * static_cast<unsigned>(base) + static_cast<unsigned>(d);
  }
  *v = neg ? -static_cast<long long>(acc) : static_cast<long long>(acc);
  return true;
}

// Float literals: [-]digits[.digits][e[+-]digits][f], at most kMaxFloatChars long, finite as a float.
bool float_literal(const Token &t, float *v) {
  size_t n = static_cast<size_t>(t.e - t.b);
  if (n == 0 || n > kMaxFloatChars) return false;
  char buf[kMaxFloatChars + 1];
  std::memcpy(buf, t.b, n);
  buf[n] = '\0';
  if (buf[n - 1] == 'f' || buf[n - 1] == 'F') buf[--n] = '\0';
  // strtod also reads hex, inf and nan: allow only the decimal form's characters.
  size_t i = buf[0] == '-' ? 1 : 0, digits = 0;
  for (; i < n; ++i) {
    char c = buf[i];
    if (Parser::digit(c)) ++digits;
    else if (!(c == '.' || c == 'e' || c == 'E' || ((c == '+' || c == '-') && (buf[i - 1] == 'e' || buf[i - 1] == 'E'))))
      return false;
  }
  if (digits == 0) return false;
  char *stop = nullptr;
  errno = 0;
  double d = std::strtod(buf, &stop);
  if (*stop != '\0' || !std::isfinite(d) || std::fabs(d) > 3.4028234663852886e38) return false;
  *v = static_cast<float>(d);
  return true;
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
constexpr int kNumMacros = sizeof kMacros / sizeof kMacros[0];
constexpr int kHash = kNumMacros - 1;

struct ArraySpec {
  const char *name, *type;
  int ndims;
  bool in_float_block, required;
};

const ArraySpec kArrays[] = {
    {"pour_weights_w", "int16_t", 2, false, true},
    {"pour_weights_action_levels_q15", "int16_t", 1, false, true},
    {"pour_weights_w_float", "float", 2, true, false},
};
constexpr int kNumArrays = sizeof kArrays / sizeof kArrays[0];

struct Macro {
  bool set = false;
  long long value = 0;
  int line = 0;
};

// One array as read: declared dimensions (-1 for []), the shape of its initializer, its values.
struct Array {
  bool found = false;
  int line = 0;
  long long dims[2] = {0, 0};
  int rows = 0, row_len[kMaxRows] = {}, len = 0; // 2-D: rows and their lengths; 1-D: len
  double values[kMaxRows * kMaxCols] = {};
  int value_line[kMaxRows * kMaxCols] = {};
};

struct Reader {
  Parser ps;
  Macro macros[kNumMacros];
  Array arrays[kNumArrays];
  char stack[2] = {0, 0}; // open conditionals: 'g' (#ifndef POUR_WEIGHTS_H), 'f' (#ifdef ..._FLOAT_REFERENCE)
  int depth = 0, stack_line[2] = {0, 0};

  int fail_tok(const char *what) {
    return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s, got %s", what, quoted(ps.tok).c_str());
  }

  int directive() {
    int rc = ps.next();
    if (rc != POURSIM_OK) return rc;
    if (ps.tok.kind != Tok::Ident) return fail_tok("expected a directive after '#'");
    const Token d = ps.tok;
    if (d.is("include")) {
      const char *want[] = {"<", "stdint", ".", "h", ">"};
      for (const char *w : want) {
        if ((rc = ps.next()) != POURSIM_OK) return rc;
        if (!ps.tok.is(w)) return fail_tok("only #include <stdint.h> is allowed");
      }
    } else if (d.is("ifndef") || d.is("ifdef")) {
      if ((rc = ps.next()) != POURSIM_OK) return rc;
      bool guard = d.is("ifndef") && ps.tok.is("POUR_WEIGHTS_H") && depth == 0;
      bool fref = d.is("ifdef") && ps.tok.is("POUR_WEIGHTS_FLOAT_REFERENCE") && (depth == 0 || stack[depth - 1] == 'g');
      if (!guard && !fref)
        return fail_tok("only '#ifndef POUR_WEIGHTS_H' around the file and '#ifdef POUR_WEIGHTS_FLOAT_REFERENCE' "
                        "inside it are allowed");
      stack_line[depth] = d.line;
      stack[depth++] = guard ? 'g' : 'f';
    } else if (d.is("endif")) {
      if (depth == 0) return ps.fail(POURSIM_EPARSE, d.line, "#endif without #ifndef or #ifdef");
      --depth;
    } else if (d.is("define")) {
      if ((rc = ps.next()) != POURSIM_OK) return rc;
      const Token key = ps.tok;
      if (key.kind != Tok::Ident) return fail_tok("expected a macro name after #define");
      if ((rc = ps.next()) != POURSIM_OK) return rc;
      if (key.is("POUR_WEIGHTS_H")) {
        if (ps.tok.kind != Tok::Newline && ps.tok.kind != Tok::End) return fail_tok("POUR_WEIGHTS_H takes no value");
        return POURSIM_OK;
      }
      int m = 0;
      while (m < kNumMacros && !key.is(kMacros[m].name)) ++m;
      if (m == kNumMacros)
        return ps.fail(POURSIM_EPARSE, key.line, "unknown macro %s (docs/weights-h.md lists the allowed ones)",
                       quoted(key).c_str());
      const char *mname = kMacros[m].name;
      if (depth > 0 && stack[depth - 1] == 'f')
        return ps.fail(POURSIM_EPARSE, key.line, "%s is inside #ifdef POUR_WEIGHTS_FLOAT_REFERENCE", mname);
      if (macros[m].set) return ps.fail(POURSIM_EPARSE, key.line, "%s is defined twice", mname);
      const Token v = ps.tok;
      if (v.kind == Tok::Newline || v.kind == Tok::End)
        return ps.fail(POURSIM_EPARSE, key.line, "%s has no value", mname);
      long long value = 0;
      bool overflow = false;
      if (v.kind != Tok::Number || !int_literal(v, m == kHash, &value, &overflow))
        return ps.fail(POURSIM_EPARSE, key.line, "%s: %s is not a plain %s integer (no suffix, no leading 0)", mname,
                       quoted(v).c_str(), m == kHash ? "decimal or hex" : "decimal");
      if (overflow || value < kMacros[m].min || value > kMacros[m].max)
        return ps.fail(POURSIM_EINVAL, key.line, "%s = %s is out of range: %s", mname, quoted(v).c_str(), kMacros[m].range);
      macros[m] = Macro{true, value, key.line};
      if ((rc = ps.next()) != POURSIM_OK) return rc;
    } else {
      return ps.fail(POURSIM_EPARSE, d.line, "directive #%s is not allowed in a weights.h",
                     std::string(d.b, std::min<size_t>(static_cast<size_t>(d.e - d.b), 40)).c_str());
    }
    if (!d.is("define") && (rc = ps.next()) != POURSIM_OK) return rc; // #define has read past its value
    if (ps.tok.kind != Tok::Newline && ps.tok.kind != Tok::End) return fail_tok("expected the end of the directive");
    return POURSIM_OK;
  }

  // The next token, skipping line ends (a declaration may span lines).
  int next_code() {
    int rc;
    do {
      if ((rc = ps.next()) != POURSIM_OK) return rc;
    } while (ps.tok.kind == Tok::Newline);
    return POURSIM_OK;
  }

  int expect(char c, const char *what) {
    int rc = next_code();
    if (rc != POURSIM_OK) return rc;
    if (ps.tok.kind == Tok::End) return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s ends early (truncated)", what);
    if (!ps.tok.punct(c)) {
      char m[160];
      std::snprintf(m, sizeof m, "%s: expected '%c'", what, c);
      return fail_tok(m);
    }
    return POURSIM_OK;
  }

  // One value of array a at flat index i, at the current token.
  int value(int ai, int row, int col, int flat) {
    const ArraySpec &spec = kArrays[ai];
    Array &a = arrays[ai];
    char where[96];
    if (spec.ndims == 2) std::snprintf(where, sizeof where, "%s[%d][%d]", spec.name, row, col);
    else std::snprintf(where, sizeof where, "%s[%d]", spec.name, col);
    const Token &t = ps.tok;
    if (t.kind == Tok::End) return ps.fail(POURSIM_EPARSE, t.line, "%s ends before its closing '}' (truncated)", spec.name);
    if (spec.type[0] == 'f') {
      float f = 0;
      if (t.kind != Tok::Number || !float_literal(t, &f))
        return ps.fail(POURSIM_EINVAL, t.line, "%s = %s is not a finite float", where, quoted(t).c_str());
      a.values[flat] = static_cast<double>(f);
    } else {
      long long v = 0;
      bool overflow = false;
      if (t.kind != Tok::Number || !int_literal(t, false, &v, &overflow) || overflow || v < INT16_MIN || v > INT16_MAX)
        return ps.fail(POURSIM_EINVAL, t.line, "%s = %s is not an int16 (plain decimal, no suffix)", where,
                       quoted(t).c_str());
      a.values[flat] = static_cast<double>(v);
    }
    a.value_line[flat] = t.line;
    return POURSIM_OK;
  }

  // "{ v, v, ... }" (the opening brace is the current token); counts into *len, at most kMaxCols values.
  int list(int ai, int row, int *len) {
    const ArraySpec &spec = kArrays[ai];
    *len = 0;
    for (;;) {
      int rc = next_code();
      if (rc != POURSIM_OK) return rc;
      if (ps.tok.punct('}')) return POURSIM_OK;
      if (*len == kMaxCols)
        return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s%s has more than %d values", spec.name,
                       spec.ndims == 2 ? (" row " + std::to_string(row)).c_str() : "", kMaxCols);
      if ((rc = value(ai, row, *len, row * kMaxCols + *len)) != POURSIM_OK) return rc;
      ++*len;
      if ((rc = next_code()) != POURSIM_OK) return rc;
      if (ps.tok.punct('}')) return POURSIM_OK;
      if (ps.tok.kind == Tok::End)
        return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s ends before its closing '}' (truncated)", spec.name);
      if (!ps.tok.punct(',')) return fail_tok((std::string(spec.name) + ": expected ',' or '}'").c_str());
    }
  }

  // "static const TYPE NAME[d]...[d] = {...};" (the current token is "static").
  int declaration() {
    int rc;
    const int line = ps.tok.line;
    if ((rc = next_code()) != POURSIM_OK) return rc;
    if (!ps.tok.is("const")) return fail_tok("expected 'static const'");
    if ((rc = next_code()) != POURSIM_OK) return rc;
    const Token type = ps.tok;
    if ((rc = next_code()) != POURSIM_OK) return rc;
    const Token nm = ps.tok;
    int ai = 0;
    while (ai < kNumArrays && !nm.is(kArrays[ai].name)) ++ai;
    if (type.kind != Tok::Ident || nm.kind != Tok::Ident || ai == kNumArrays)
      return ps.fail(POURSIM_EPARSE, line, "unexpected declaration (only the arrays of docs/weights-h.md are allowed)");
    const ArraySpec &spec = kArrays[ai];
    Array &a = arrays[ai];
    if (a.found) return ps.fail(POURSIM_EPARSE, line, "%s is defined twice", spec.name);
    if (!type.is(spec.type))
      return ps.fail(POURSIM_EPARSE, line, "%s is declared %s, expected %s", spec.name, quoted(type).c_str(), spec.type);
    bool in_fref = depth > 0 && stack[depth - 1] == 'f';
    if (in_fref != spec.in_float_block)
      return ps.fail(POURSIM_EPARSE, line, "%s must be %s #ifdef POUR_WEIGHTS_FLOAT_REFERENCE", spec.name,
                     spec.in_float_block ? "inside" : "outside");
    a.found = true;
    a.line = line;
    int nd = 0;
    for (;;) {
      if ((rc = next_code()) != POURSIM_OK) return rc;
      if (!ps.tok.punct('[')) break;
      if (nd == spec.ndims)
        return ps.fail(POURSIM_EPARSE, line, "%s has more than %d dimension%s", spec.name, spec.ndims,
                       spec.ndims > 1 ? "s" : "");
      if ((rc = next_code()) != POURSIM_OK) return rc;
      long long dim = -1;
      const Token d = ps.tok;
      if (d.punct(']')) {
        if (nd > 0) return ps.fail(POURSIM_EPARSE, line, "%s: only the first dimension may be empty", spec.name);
      } else {
        int m = 0;
        while (m < kHash && !d.is(kMacros[m].name)) ++m;
        bool overflow = false;
        if (d.kind == Tok::Ident && m < kHash && macros[m].set) dim = macros[m].value;
        else if (d.kind != Tok::Number || !int_literal(d, false, &dim, &overflow) || overflow || dim <= 0)
          return ps.fail(POURSIM_EPARSE, line, "%s has an unknown dimension %s (a positive number or a macro defined above)",
                         spec.name, quoted(d).c_str());
        if ((rc = next_code()) != POURSIM_OK) return rc;
        if (!ps.tok.punct(']')) return fail_tok((std::string(spec.name) + ": expected ']'").c_str());
      }
      a.dims[nd++] = dim;
    }
    if (nd != spec.ndims)
      return ps.fail(POURSIM_EPARSE, line, "%s has %d dimension%s, expected %d", spec.name, nd, nd == 1 ? "" : "s",
                     spec.ndims);
    if (ps.tok.kind == Tok::End) return ps.fail(POURSIM_EPARSE, line, "%s ends early (truncated)", spec.name);
    if (!ps.tok.punct('=')) return fail_tok((std::string(spec.name) + ": expected '='").c_str());
    if ((rc = expect('{', spec.name)) != POURSIM_OK) return rc;
    if (spec.ndims == 1) {
      if ((rc = list(ai, 0, &a.len)) != POURSIM_OK) return rc;
    } else {
      for (;;) {
        if ((rc = next_code()) != POURSIM_OK) return rc;
        if (ps.tok.punct('}')) break;
        if (ps.tok.kind == Tok::End)
          return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s ends before its closing '}' (truncated)", spec.name);
        if (!ps.tok.punct('{')) return fail_tok((std::string(spec.name) + ": each row must be a '{...}' list").c_str());
        if (a.rows == kMaxRows)
          return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s has more than %d rows", spec.name, kMaxRows);
        if ((rc = list(ai, a.rows, &a.row_len[a.rows])) != POURSIM_OK) return rc;
        ++a.rows;
        if ((rc = next_code()) != POURSIM_OK) return rc;
        if (ps.tok.punct('}')) break;
        if (ps.tok.kind == Tok::End)
          return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s ends before its closing '}' (truncated)", spec.name);
        if (!ps.tok.punct(',')) return fail_tok((std::string(spec.name) + ": expected ',' or '}' after a row").c_str());
      }
    }
    if ((rc = next_code()) != POURSIM_OK) return rc;
    if (ps.tok.kind == Tok::End) return ps.fail(POURSIM_EPARSE, ps.tok.line, "%s: no ';' at the end (truncated)", spec.name);
    if (!ps.tok.punct(';')) return fail_tok((std::string(spec.name) + ": expected ';'").c_str());
    return POURSIM_OK;
  }

  int read() {
    int rc = ps.check_bytes();
    if (rc != POURSIM_OK) return rc;
    bool line_start = true;
    for (;;) {
      if ((rc = ps.next()) != POURSIM_OK) return rc;
      if (ps.tok.kind == Tok::End) break;
      if (ps.tok.kind == Tok::Newline) {
        line_start = true;
        continue;
      }
      if (ps.tok.kind == Tok::Hash) {
        if (!line_start) return fail_tok("a '#' must start its line");
        if ((rc = directive()) != POURSIM_OK) return rc;
        line_start = true; // the directive consumed its line end
      } else if (ps.tok.is("static")) {
        if ((rc = declaration()) != POURSIM_OK) return rc;
        line_start = false;
      } else {
        return fail_tok("expected a #directive or a 'static const' array");
      }
    }
    if (depth > 0)
      return ps.fail(POURSIM_EPARSE, stack_line[depth - 1], "%s is never closed by #endif (truncated?)",
                     stack[depth - 1] == 'g' ? "#ifndef POUR_WEIGHTS_H" : "#ifdef POUR_WEIGHTS_FLOAT_REFERENCE");
    return POURSIM_OK;
  }

  // Shapes against the macros, once the whole file is read.
  int check_shape(int ai, long long n) {
    const ArraySpec &spec = kArrays[ai];
    const Array &a = arrays[ai];
    const long long want[2] = {spec.ndims == 2 ? kMaxRows : n, n};
    for (int k = 0; k < spec.ndims; ++k)
      if (a.dims[k] != -1 && a.dims[k] != want[k])
        return ps.fail(POURSIM_EPARSE, a.line, "%s dimension %d is %lld, expected %lld", spec.name, k, a.dims[k], want[k]);
    if (spec.ndims == 1) {
      if (a.len != n) return ps.fail(POURSIM_EPARSE, a.line, "%s has %d values, expected %lld", spec.name, a.len, n);
      return POURSIM_OK;
    }
    if (a.rows != kMaxRows)
      return ps.fail(POURSIM_EPARSE, a.line, "%s has %d rows, expected %d", spec.name, a.rows, kMaxRows);
    for (int r = 0; r < a.rows; ++r)
      if (a.row_len[r] != n)
        return ps.fail(POURSIM_EPARSE, a.line, "%s row %d has %d values, expected %lld", spec.name, r, a.row_len[r], n);
    return POURSIM_OK;
  }
};

} // namespace

extern "C" int poursim_weights_parse(const char *text, size_t len, const char *name, poursim_weights_file_t *out,
                                     char *err, size_t err_len) {
  if (text == nullptr || out == nullptr) return set_error(err, err_len, POURSIM_EINVAL, "weights: NULL argument");
  if (name == nullptr) name = "weights.h";
  std::memset(out, 0, sizeof *out);
  static_assert(kMaxRows == POUR_POLICY_N_FEATURES, "W has one row per feature");
  // Large (two 6x16 value tables per array): on the heap, not the caller's stack.
  std::unique_ptr<Reader> rd(new Reader{Parser{text, text + len, name, err, err_len, text, 1, Token{}}, {}, {}, {0, 0}, 0, {0, 0}});
  Parser &ps = rd->ps;
  int rc = rd->read();
  if (rc != POURSIM_OK) return rc;

  const Macro *m = rd->macros;
  for (int k = 0; k < kNumMacros; ++k)
    if (!m[k].set) return ps.fail(POURSIM_EPARSE, 0, "%s is missing", kMacros[k].name);
  out->format = static_cast<int32_t>(m[0].value);
  out->n_features = static_cast<int32_t>(m[1].value);
  out->n_actions = static_cast<int32_t>(m[2].value);
  out->w_frac_bits = static_cast<int32_t>(m[3].value);
  out->decision_period_ms = static_cast<int32_t>(m[4].value);
  out->theta_min_urad = static_cast<int32_t>(m[5].value);
  out->theta_max_urad = static_cast<int32_t>(m[6].value);
  out->omega_max_urad_s = static_cast<int32_t>(m[7].value);
  out->tau_max_mnm = static_cast<int32_t>(m[8].value);
  out->content_hash = static_cast<uint32_t>(m[kHash].value);
  if (out->theta_max_urad <= out->theta_min_urad)
    return ps.fail(POURSIM_EINVAL, m[6].line, "POUR_WEIGHTS_THETA_MAX_URAD = %d must be > POUR_WEIGHTS_THETA_MIN_URAD = %d",
                   out->theta_max_urad, out->theta_min_urad);
  const int n = out->n_actions;
  for (int ai = 0; ai < kNumArrays; ++ai) {
    const Array &a = rd->arrays[ai];
    if (!a.found) {
      if (kArrays[ai].required) return ps.fail(POURSIM_EPARSE, 0, "%s is missing", kArrays[ai].name);
      continue;
    }
    if ((rc = rd->check_shape(ai, n)) != POURSIM_OK) return rc;
  }
  const Array &w = rd->arrays[0], &lv = rd->arrays[1], &wf = rd->arrays[2];
  for (int r = 0; r < kMaxRows; ++r)
    for (int c = 0; c < n; ++c) {
      out->w[r * n + c] = static_cast<int16_t>(w.values[r * kMaxCols + c]);
      out->w_float[r * n + c] = static_cast<float>(wf.values[r * kMaxCols + c]);
    }
  for (int i = 0; i < n; ++i) {
    out->levels[i] = static_cast<q15_t>(lv.values[i]);
    if (i > 0 && out->levels[i] <= out->levels[i - 1])
      return ps.fail(POURSIM_EINVAL, lv.value_line[i], "pour_weights_action_levels_q15 must be strictly increasing (index %d)", i);
  }
  out->has_float_reference = wf.found ? 1 : 0;

  pour_policy_weights_t view;
  poursim_weights_view(out, &view);
  uint32_t h = pour_policy_weights_hash(&view);
  if (h != out->content_hash)
    return ps.fail(POURSIM_EINVAL, m[kHash].line,
                   "POUR_WEIGHTS_CONTENT_HASH is 0x%08x but the content hashes to 0x%08x (edited or corrupted)",
                   out->content_hash, h);
  pour_status_t st = pour_policy_weights_validate(&view);
  if (st != POUR_OK) return ps.fail(POURSIM_EINVAL, 0, "the firmware core refuses these weights: %s", pour_status_name(st));
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
