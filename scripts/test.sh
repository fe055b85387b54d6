#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds and tests everything: host (all labels), host under ASan+UBSan (the C/C++ tests but the slow
# physics ones, and the pytest files that drive our programs), the Cortex-M4 image with its unit tests on an
# emulated MCU, and the libFuzzer targets (clang, ASan+UBSan) run on their corpus and briefly fuzzed.
# Installs what is missing first. Tests run in parallel (ctest -j, one job per core; POUR_TEST_JOBS=N to
# change it); the tests that share a guest or a port hold a ctest RESOURCE_LOCK, the ones that pace by the
# wall clock run alone (RUN_SERIAL). Warnings are errors here (POUR_WERROR, which the presets read from the
# environment); a user's build only warns. Each preset is judged by ctest's exit status; the counts come
# from its JUnit report. Prints the wall time of each preset's build and tests at the end.
#   ./scripts/test.sh         the quick suite: every test but those labelled `slow` (about 10 min on 2
#                             cores once built); every label keeps tests in it, and the run fails if one
#                             has none
#   ./scripts/test.sh --all   every test, the `slow` ones too (the SB3 extra, minutes of physics, the long
#                             CAN bench and LCM logging runs, the README's training commands), and each
#                             fuzz target fuzzed for 120 s instead of 10 s: what CI (.ci/run) runs
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
. scripts/lib/cli.sh
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"
ALL=0
for arg in "$@"; do
  case "$arg" in
    --all) ALL=1 ;;
    *) echo "test.sh: unknown argument '$arg' (see --help)" >&2; exit 2 ;;
  esac
done
JOBS=${POUR_TEST_JOBS:-$(nproc)}
[[ $JOBS =~ ^[1-9][0-9]*$ ]] || { echo "test.sh: POUR_TEST_JOBS must be a positive integer, not '$JOBS'" >&2; exit 2; }
./scripts/setup.sh || exit 1
export POUR_WERROR=ON
if [ "$ALL" = 1 ]; then SUFFIX=-all FUZZ_SECONDS=120; else SUFFIX="" FUZZ_SECONDS=10; fi

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", a - b }'; }
passed=0 failed=0 status=0
timings=()
t_start=$(now)
for preset in host host-asan cortex-m4 host-fuzz; do
  printf '\n=== %s%s ===\n' "$preset" "$SUFFIX"
  extra=()
  [ "$preset" = host-fuzz ] && extra=(-DPOUR_FUZZ_SECONDS="$FUZZ_SECONDS")
  t0=$(now)
  if ! { cmake --preset "$preset" "${extra[@]}" && cmake --build --preset "$preset"; }; then
    echo "error: preset $preset did not build"
    status=1
    timings+=("$preset $(elapsed "$(now)" "$t0") - 0 0")
    continue
  fi
  t1=$(now)
  # Every label of the preset's tests keeps at least one test outside `slow` (the quick tier).
  if ! python3 scripts/lib/test_tiers.py "$preset"; then
    status=1
  fi
  junit="$ROOT/build/$preset/junit.xml"
  rm -f "$junit"
  ctest --preset "$preset$SUFFIX" --parallel "$JOBS" --output-junit "$junit"
  rc=$?
  t2=$(now)
  # tests= counts every test run; failures= those that failed (errors: could not run).
  counts=$(python3 - "$junit" <<'EOF'
import sys
import xml.etree.ElementTree as ET
try:
    s = ET.parse(sys.argv[1]).getroot()
except (OSError, ET.ParseError):
    print("0 0")
    raise SystemExit
bad = int(s.get("failures", 0)) + int(s.get("errors", 0))
print(int(s.get("tests", 0)) - int(s.get("skipped", 0)) - int(s.get("disabled", 0)), bad)
EOF
)
  read -r total nfail <<<"$counts"
  if [ "$total" = 0 ]; then
    echo "error: preset $preset ran no tests (ctest exit $rc)"
    status=1
  fi
  passed=$((passed + total - nfail))
  failed=$((failed + nfail))
  [ "$rc" = 0 ] || status=1
  timings+=("$preset $(elapsed "$t1" "$t0") $(elapsed "$t2" "$t1") $total $nfail")
done
t_end=$(now)

echo
echo "wall time by preset ($([ "$ALL" = 1 ] && echo "--all" || echo quick), ctest -j$JOBS):"
printf '  %-10s %9s %9s %6s %6s\n' preset "build s" "tests s" tests failed
for row in "${timings[@]}"; do
  read -r p b t n f <<<"$row"
  printf '  %-10s %9.1f %9s %6s %6s\n' "$p" "$b" "$( [ "$t" = - ] && echo - || printf '%.1f' "$t")" "$n" "$f"
done
printf '  %-10s %19.1f  (set-up excluded)\n' total "$(elapsed "$t_end" "$t_start")"
echo
echo "${passed} passed, ${failed} failed"
[ "$failed" = 0 ] || status=1
exit "$status"
