#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The main job: one pour of the simulated bucket with the shipped trained policy, run through the real
# firmware control step (linked in-process) and the full drive, with the numbers printed and a rendered
# picture written.
# Installs what is missing first. Extra arguments go to host_sim (e.g. --seed 7, --episodes 20).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
./scripts/setup.sh
cmake --preset host >/dev/null
cmake --build --preset host --target host_sim
mkdir -p out
# host_sim --render runs the tools' pour-render, from the venv's bin.
export PATH="$ROOT/.venv/bin:$PATH"
# drive=1: through the full drive (the firmware's current loop, the motor, inverter and bus model,
# docs/motor.md); host_sim then prints the peak phase current and the peak bus voltage.
./build/host/bin/host_sim --policy policy/weights.h --seed 1 --set drive=1 --render out/pour.gif "$@"
echo
echo "Rendered pour: out/pour.gif (animation) and out/pour.png (snapshot)"
