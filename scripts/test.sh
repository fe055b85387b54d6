#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds and tests everything: host (all labels), host under ASan+UBSan (unit tests), and the
# Cortex-M4 image with its unit tests on an emulated MCU. Installs what is missing first.
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
./scripts/setup.sh || exit 1

passed=0 failed=0 status=0
for preset in host host-asan cortex-m4; do
  printf '\n=== %s ===\n' "$preset"
  log=$(mktemp)
  cmake --workflow --preset "$preset" 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  line=$(grep -E '^[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "$log" | tail -n 1)
  rm -f "$log"
  if [ -z "$line" ]; then
    echo "error: preset $preset did not get as far as running its tests (exit $rc)"
    status=1
    continue
  fi
  total=$(sed -E 's/.* out of ([0-9]+).*/\1/' <<<"$line")
  nfail=$(sed -E 's/.*, ([0-9]+) tests? failed.*/\1/' <<<"$line")
  passed=$((passed + total - nfail))
  failed=$((failed + nfail))
  [ "$rc" = 0 ] || status=1
done

echo
echo "${passed} passed, ${failed} failed"
[ "$failed" = 0 ] || status=1
exit "$status"
