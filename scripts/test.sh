#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds and tests everything: host (all labels), host under ASan+UBSan (the C/C++ tests but the slow
# physics ones, and the pytest files that drive our programs), the Cortex-M4
# image with its unit tests on an emulated MCU, and the libFuzzer targets (clang, ASan+UBSan) run on
# their corpus and briefly fuzzed. Installs what is missing first. Warnings are errors here
# (POUR_WERROR, which the presets read from the environment); a user's build only warns.
# Each preset is judged by ctest's exit status; the counts come from its JUnit report.
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
. scripts/lib/cli.sh
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"
./scripts/setup.sh || exit 1
export POUR_WERROR=ON

passed=0 failed=0 status=0
for preset in host host-asan cortex-m4 host-fuzz; do
  printf '\n=== %s ===\n' "$preset"
  if ! { cmake --preset "$preset" && cmake --build --preset "$preset"; }; then
    echo "error: preset $preset did not build"
    status=1
    continue
  fi
  junit="$ROOT/build/$preset/junit.xml"
  rm -f "$junit"
  ctest --preset "$preset" --output-junit "$junit"
  rc=$?
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
done

echo
echo "${passed} passed, ${failed} failed"
[ "$failed" = 0 ] || status=1
exit "$status"
