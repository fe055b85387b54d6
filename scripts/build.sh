#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds what the README's and docs' commands run, without running any test: libpoursim.so (the trainer's
# and pour-eval's simulator), host_sim, pour_controller, can_bridge, fault_pour and the generated LCM types
# (Python for pour-lcm-*, the jar for pour-lcm-spy), in build/host. Installs what is missing first.
#   ./scripts/build.sh          those programs
#   ./scripts/build.sh --all    the whole host preset, the test programs too (still runs no test)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
. scripts/lib/cli.sh
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"
TARGETS=(poursim_shared host_sim pour_controller can_bridge fault_pour pour_lcmtypes_py pour_lcmtypes_jar)
case "${1:-}" in
  --all) TARGETS=(all) ;;
  "") ;;
  *) echo "build.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
esac
./scripts/setup.sh --build
cmake --preset host >/dev/null
cmake --build --preset host --target "${TARGETS[@]}"
