#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# run_fuzz.sh <fuzz target binary> <seconds> <work dir>
# Runs the target on its committed corpus and regression inputs (tests/fuzz/corpus/<name>,
# tests/fuzz/regressions/<name>: every one must pass), then fuzzes for <seconds> with its dictionary,
# new inputs going to <work dir>/<name>/corpus (not committed). A crash, leak, sanitizer report or broken
# property exits non-zero and leaves the input in <work dir>/<name>/crash-*: commit it to
# regressions/<name> with the fix. Prints libFuzzer's final stats (executions, exec/s, edge coverage).
set -euo pipefail
bin=$1 seconds=$2 work=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
name=$(basename "$bin")
mkdir -p "$work/$name/corpus" "$here/corpus/$name"
args=(-max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$work/$name/" -max_len=8192 -timeout=10
      -rss_limit_mb=2048)
[ -f "$here/$name.dict" ] && args+=(-dict="$here/$name.dict")
dirs=("$work/$name/corpus" "$here/corpus/$name")
[ -d "$here/regressions/$name" ] && dirs+=("$here/regressions/$name")
exec "$bin" "${args[@]}" "${dirs[@]}"
