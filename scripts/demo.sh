#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The main job: one pour of the simulated bucket with the shipped trained policy, run through the real
# firmware control step (linked in-process) and the full drive (docs/motor.md), with the numbers printed
# and a rendered picture written.
# Installs what is missing first, and builds (scripts/build.sh) everything the README's and docs' commands
# run: libpoursim.so, host_sim, pour_controller, can_bridge, fault_pour, the LCM types. Extra arguments go
# to host_sim (e.g. --seed 7, --episodes 20; build/host/bin/host_sim --help lists them).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
. scripts/lib/cli.sh
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"
./scripts/build.sh
mkdir -p out
# host_sim --render runs the tools' pour-render, from the venv's bin.
export PATH="$ROOT/.venv/bin:$PATH"
# drive=1: through the full drive (the firmware's current loop, the motor, inverter and bus model,
# docs/motor.md); host_sim then prints the peak phase current and the peak bus voltage.
./build/host/bin/host_sim --policy policy/weights.h --seed 1 --set drive=1 --render out/pour.gif "$@"
echo
echo "Rendered pour: out/pour.gif (animation) and out/pour.png (snapshot)"
