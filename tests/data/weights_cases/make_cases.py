# SPDX-License-Identifier: MIT
"""Regenerates the weights.h cases of this folder from policy/example_weights.h: one edit each.

cases.tsv lists, per file: what host_sim's parser and pour.policy.weights_h must both do (accept or refuse),
a text their error message must contain, and what the firmware build does with it (ok: compiles and
the core's init accepts it; build: the compiler refuses it; build-named: the compiler refuses it with a
diagnostic that names that text too (the checks in firmware/src/weights_compiled.c); init: compiles, the core's init refuses it
(content hash); stricter: the compiler accepts it (float reference: when compiled without
POUR_WEIGHTS_FLOAT_REFERENCE) but our parsers refuse it on purpose, see docs/weights-h.md). Run from the repository root: python3 tests/data/weights_cases/make_cases.py
"""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
HERE = Path(__file__).resolve().parent
EXAMPLE = (ROOT / "policy/example_weights.h").read_bytes()


def sub(pattern: bytes, repl: bytes, text: bytes = EXAMPLE, count: int = 1) -> bytes:
    out, n = re.subn(pattern, repl, text, count=count)
    assert n, pattern
    return out


W_FIRST = rb"(pour_weights_w\[[^\n]*\n    \{)4096"
LEVELS = rb"static const int16_t pour_weights_action_levels_q15"
FLOAT = rb"#ifdef POUR_WEIGHTS_FLOAT_REFERENCE\n"
FLOAT_BLOCK = re.compile(rb"#ifdef POUR_WEIGHTS_FLOAT_REFERENCE\n(.*?\n)#endif\n", re.S)
LONG = b"x" * 30000

# (name, verdict, message, firmware, text)
CASES = [
    ("ok_example", "accept", "", "ok", EXAMPLE),
    ("ok_crlf", "accept", "", "ok", EXAMPLE.replace(b"\n", b"\r\n")),
    ("ok_long_comment_on_define", "accept", "", "ok",
     sub(rb"(#define POUR_WEIGHTS_N_ACTIONS 11)", rb"\1 /* " + LONG + rb" */")),
    ("ok_long_comment_in_array", "accept", "", "ok", sub(W_FIRST, rb"\1/* " + LONG + rb" */ 4096")),
    ("ok_long_line_comment", "accept", "", "ok", sub(rb"(#define POUR_WEIGHTS_FORMAT 1)", rb"\1 // " + LONG)),
    ("ok_comments_everywhere", "accept", "", "ok",
     sub(rb"static const int16_t pour_weights_w\[", b"static /* a */ const\n\tint16_t // b\n  pour_weights_w /* c\n d */[",
         sub(rb"#define POUR_WEIGHTS_TAU_MAX_MNM", b"/* before */ # /* mid */ define\tPOUR_WEIGHTS_TAU_MAX_MNM",
             sub(rb"\A", b"// leading comment\n\n\n")))),
    ("ok_no_float_reference", "accept", "", "ok", FLOAT_BLOCK.sub(b"", EXAMPLE)),
    ("ok_numeric_and_empty_dims", "accept", "", "ok",
     sub(rb"pour_weights_w\[POUR_WEIGHTS_N_FEATURES\]\[POUR_WEIGHTS_N_ACTIONS\]", b"pour_weights_w[][11]",
         sub(rb"pour_weights_action_levels_q15\[POUR_WEIGHTS_N_ACTIONS\]", b"pour_weights_action_levels_q15[]"))),
    ("ok_trailing_commas", "accept", "", "ok", sub(rb"32767\}", b"32767,}", sub(rb"10650\}", b"10650},"))),
    ("ok_hash_decimal", "accept", "", "ok", sub(rb"0x09b1269bu", str(0x09b1269b).encode())),
    ("ok_no_guard_no_include", "accept", "", "ok",
     sub(rb"#endif\n\Z", b"", sub(rb"#ifndef POUR_WEIGHTS_H\n#define POUR_WEIGHTS_H\n#include <stdint.h>\n", b""))),
    # Refused: what the issue found, then one per rule of the grammar.
    ("macro_value_50kb", "refuse", "POUR_WEIGHTS_TAU_MAX_MNM", "build",
     sub(rb"POUR_WEIGHTS_TAU_MAX_MNM 20000", b"POUR_WEIGHTS_TAU_MAX_MNM 2" + b"0" * 50000)),
    ("token_20kb_in_array", "refuse", "pour_weights_w[0][0]", "build", sub(W_FIRST, rb"\g<1>4096" + b"1" * 20000)),
    ("identifier_20kb", "refuse", "expected a #directive", "build", sub(rb"\A", b"y" * 20000 + b"\n")),
    ("minus_one_u_macro", "refuse", "POUR_WEIGHTS_THETA_MIN_URAD", "build",
     sub(rb"POUR_WEIGHTS_THETA_MIN_URAD 0", b"POUR_WEIGHTS_THETA_MIN_URAD -1u")),
    ("minus_one_u_weight", "refuse", "pour_weights_w[0][0]", "build", sub(W_FIRST, rb"\1-1u")),
    ("long_suffix", "refuse", "POUR_WEIGHTS_TAU_MAX_MNM", "stricter",
     sub(rb"POUR_WEIGHTS_TAU_MAX_MNM 20000", b"POUR_WEIGHTS_TAU_MAX_MNM 20000L")),
    ("octal_leading_zero", "refuse", "POUR_WEIGHTS_DECISION_PERIOD_MS", "init",
     sub(rb"POUR_WEIGHTS_DECISION_PERIOD_MS 10", b"POUR_WEIGHTS_DECISION_PERIOD_MS 010")),
    ("hash_negative", "refuse", "POUR_WEIGHTS_CONTENT_HASH", "build", sub(rb"0x09b1269bu", b"-1")),
    ("hash_too_big", "refuse", "POUR_WEIGHTS_CONTENT_HASH", "build", sub(rb"0x09b1269bu", b"0x109b1269bu")),
    ("hash_mismatch", "refuse", "edited or corrupted", "init", sub(rb"0x09b1269bu", b"0x09b1269cu")),
    # A hash >= 0x80000000 is a valid uint32_t: it compiles (only the content check refuses this one).
    ("hash_mismatch_high_bit", "refuse", "edited or corrupted", "init", sub(rb"0x09b1269bu", b"0xfedcba98u")),
    ("nan_float_reference", "refuse", "pour_weights_w_float[0][0]", "stricter",
     sub(rb"(pour_weights_w_float\[[^\n]*\n    \{)8\.0f", rb"\1NAN")),
    ("inf_float_reference", "refuse", "pour_weights_w_float[0][0]", "stricter",
     sub(rb"(pour_weights_w_float\[[^\n]*\n    \{)8\.0f", rb"\g<1>1e999f")),
    ("hex_float_reference", "refuse", "pour_weights_w_float[0][0]", "stricter",
     sub(rb"(pour_weights_w_float\[[^\n]*\n    \{)8\.0f", rb"\g<1>0x1p3f")),
    ("nul_byte", "refuse", "NUL byte", "stricter", sub(rb"/\* theta", b"/* \0 theta")),
    ("lone_cr", "refuse", "carriage return", "build",
     sub(rb"(#define POUR_WEIGHTS_FORMAT 1)\n", rb"\1 // note\r#define POUR_WEIGHTS_FORMAT 2" + b"\n")),
    ("continued_line_comment", "refuse", "line continuation", "build",
     sub(rb"(#define POUR_WEIGHTS_FORMAT 1)\n", rb"\1 // note \\" + b"\n#define POUR_WEIGHTS_FORMAT 2\n")),
    ("trigraph_continuation", "refuse", "line continuation", "build",
     sub(rb"(#define POUR_WEIGHTS_FORMAT 1)\n", rb"\1 // note ??/" + b"\n")),
    ("unterminated_comment", "refuse", "comment is not closed", "build", EXAMPLE + b"/* no end"),
    ("missing_endif", "refuse", "never closed by #endif", "build", sub(rb"#endif\n\Z", b"")),
    ("stray_endif", "refuse", "#endif without", "build", EXAMPLE + b"#endif\n"),
    ("undef_directive", "refuse", "directive #undef", "build", EXAMPLE.replace(b"#endif\n#endif\n", b"#endif\n#undef POUR_WEIGHTS_N_ACTIONS\n#endif\n")),
    ("unknown_macro", "refuse", "unknown macro", "stricter", sub(rb"(#define POUR_WEIGHTS_FORMAT 1\n)", rb"\1#define POUR_WEIGHTS_EXTRA 3" + b"\n")),
    ("function_like_macro", "refuse", "unexpected character '('", "build",
     sub(rb"#define POUR_WEIGHTS_N_ACTIONS 11", b"#define POUR_WEIGHTS_N_ACTIONS(x) 11")),
    ("macro_defined_twice", "refuse", "defined twice", "stricter",
     sub(rb"(#define POUR_WEIGHTS_FORMAT 1\n)", rb"\1\1")),
    ("macro_without_value", "refuse", "has no value", "build",
     sub(rb"#define POUR_WEIGHTS_W_FRAC_BITS 9", b"#define POUR_WEIGHTS_W_FRAC_BITS")),
    ("macro_two_tokens", "refuse", "end of the directive", "build",
     sub(rb"#define POUR_WEIGHTS_N_ACTIONS 11", b"#define POUR_WEIGHTS_N_ACTIONS 11 /* a\n */ 2")),
    ("macro_in_float_block", "refuse", "inside #ifdef", "build",
     sub(FLOAT, FLOAT + b"#define POUR_WEIGHTS_FORMAT 1\n", sub(rb"#define POUR_WEIGHTS_FORMAT 1\n", b""))),
    ("separate_minus_sign", "refuse", "unexpected character '-'", "stricter", sub(W_FIRST, rb"\1- 4096")),
    ("array_defined_twice", "refuse", "defined twice", "build",
     sub(LEVELS + rb"[^\n]*\n", lambda m: m.group(0) * 2)),
    ("float_reference_outside_ifdef", "refuse", "must be inside", "stricter", FLOAT_BLOCK.sub(rb"\1", EXAMPLE)),
    ("levels_in_float_block", "refuse", "must be outside", "build",
     sub(rb"(" + LEVELS + rb"[^\n]*\n)(" + FLOAT + rb")", rb"\2\1")),
    ("flat_initializer", "refuse", "each row must be", "build",
     sub(rb"\}\,\n    \{", b",\n    ", sub(rb"= \{\n    \{", b"= {\n    ", count=1), count=5)),
    ("three_dimensions", "refuse", "more than 2 dimensions", "build",
     sub(rb"pour_weights_w\[POUR_WEIGHTS_N_FEATURES\]\[POUR_WEIGHTS_N_ACTIONS\]",
         b"pour_weights_w[POUR_WEIGHTS_N_FEATURES][POUR_WEIGHTS_N_ACTIONS][1]")),
    ("dimension_before_its_macro", "refuse", "unknown dimension", "build",
     sub(rb"#define POUR_WEIGHTS_N_ACTIONS 11\n", b"",
         sub(LEVELS, b"#define POUR_WEIGHTS_N_ACTIONS 11\n" + LEVELS))),
    ("wrong_type_float_w", "refuse", "declared 'float'", "build",
     sub(rb"int16_t pour_weights_w\[", b"float pour_weights_w[")),
    ("truncated_in_array", "refuse", "truncated", "build", EXAMPLE[: EXAMPLE.index(b"6554, 3277") + 3]),
    ("truncated_after_brace", "refuse", "truncated", "build", EXAMPLE[: EXAMPLE.index(LEVELS) - 2]),
    ("string_literal", "refuse", "unexpected character '\"'", "stricter", sub(rb"#include <stdint.h>", b'#include "stdint.h"')),
    ("non_ascii_outside_comment", "refuse", "non-ASCII", "build", sub(W_FIRST, "\\1\u00a04096".encode())),
    ("other_declaration", "refuse", "expected a #directive", "stricter", EXAMPLE + b"int pour_extra;\n"),
    ("stray_semicolon", "refuse", "expected a #directive", "stricter", sub(rb"(32767\};)", rb"\1;")),
    ("levels_not_increasing", "refuse", "strictly increasing", "init", sub(rb"-26214, -19661", b"-19661, -26214")),
    ("weight_out_of_int16", "refuse", "pour_weights_w[0][0]", "build", sub(W_FIRST, rb"\g<1>40000")),
    ("too_many_rows", "refuse", "more than 6 rows", "build",
     sub(rb"(\{-14746[^\n]*\})\n", rb"\1,\n    \1" + b"\n")),
    # The firmware build's own checks (weights_compiled.c): each must be refused by the compiler with a
    # diagnostic naming the field (build-named), and by the parsers naming it too.
    ("bad_format", "refuse", "POUR_WEIGHTS_FORMAT", "build-named",
     sub(rb"POUR_WEIGHTS_FORMAT 1", b"POUR_WEIGHTS_FORMAT 2", count=0)),
    ("wrong_features", "refuse", "POUR_WEIGHTS_N_FEATURES", "build-named",
     sub(rb"POUR_WEIGHTS_N_FEATURES 6", b"POUR_WEIGHTS_N_FEATURES 5", count=0)),
    ("too_many_actions", "refuse", "POUR_WEIGHTS_N_ACTIONS", "build-named",
     sub(rb"POUR_WEIGHTS_N_ACTIONS [0-9]+", b"POUR_WEIGHTS_N_ACTIONS 17", count=0)),
    ("frac_bits_out_of_range", "refuse", "POUR_WEIGHTS_W_FRAC_BITS", "build-named",
     sub(rb"POUR_WEIGHTS_W_FRAC_BITS [0-9]+", b"POUR_WEIGHTS_W_FRAC_BITS 16", count=0)),
    ("zero_period", "refuse", "POUR_WEIGHTS_DECISION_PERIOD_MS", "build-named",
     sub(rb"POUR_WEIGHTS_DECISION_PERIOD_MS [0-9]+", b"POUR_WEIGHTS_DECISION_PERIOD_MS 0", count=0)),
    ("inverted_theta", "refuse", "POUR_WEIGHTS_THETA_MAX_URAD", "build-named",
     sub(rb"POUR_WEIGHTS_THETA_MAX_URAD [0-9]+", b"POUR_WEIGHTS_THETA_MAX_URAD -1", count=0)),
    ("missing_tau_max", "refuse", "POUR_WEIGHTS_TAU_MAX_MNM", "build-named",
     sub(rb"\n#define POUR_WEIGHTS_TAU_MAX_MNM [^\n]*\n", b"\n", count=0)),
    ("missing_hash", "refuse", "POUR_WEIGHTS_CONTENT_HASH", "build-named",
     sub(rb"\n#define POUR_WEIGHTS_CONTENT_HASH [^\n]*\n", b"\n", count=0)),
    ("missing_levels", "refuse", "pour_weights_action_levels_q15", "build-named",
     sub(rb"\n" + LEVELS + rb"[^\n]*\n", b"\n", count=0)),
    ("wrong_shape", "refuse", "pour_weights_w", "build-named",
     sub(rb"pour_weights_w\[POUR_WEIGHTS_N_FEATURES\]\[POUR_WEIGHTS_N_ACTIONS\]",
         b"pour_weights_w[POUR_WEIGHTS_N_FEATURES][10]", count=0)),
    ("truncated_rows", "refuse", "pour_weights_w", "build-named",
     sub(rb",\n    \{[^\n]*\}(\n\}.\n" + LEVELS + b")", rb"\1",
         sub(rb"pour_weights_w\[POUR_WEIGHTS_N_FEATURES\]", b"pour_weights_w[]", count=0), count=0)),
    ("truncated_levels", "refuse", "pour_weights_action_levels_q15", "build-named",
     sub(rb"(pour_weights_action_levels_q15)\[POUR_WEIGHTS_N_ACTIONS\]( = \{[^\n]*), [-0-9]+\}", rb"\1[]\2}",
         count=0)),
    ("wrong_level_type", "refuse", "pour_weights_action_levels_q15", "build-named",
     sub(LEVELS, b"static const int32_t pour_weights_action_levels_q15", count=0)),
]


def main() -> None:
    for old in HERE.glob("*.h"):
        old.unlink()
    rows = ["# file\tverdict\tmessage contains\tfirmware build (see make_cases.py)"]
    for name, verdict, message, firmware, text in CASES:
        (HERE / f"{name}.h").write_bytes(text)
        rows.append(f"{name}.h\t{verdict}\t{message}\t{firmware}")
    (HERE / "cases.tsv").write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
