#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Flashes the firmware image into the B-G431B-ESC1 through its on-board ST-LINK with Debian's openocd
# (interface/stlink.cfg, target/stm32g4x.cfg): program, verify, reset.
#   scripts/flash.sh [IMAGE.elf]     default: build/cortex-m4/firmware/ports/cortex-m4/pour_firmware.elf
# Exit status: 0 flashed and verified; 2 bad input (no image, not an ARM ELF, no openocd); 3 no probe
# found; 1 openocd failed otherwise (its output is shown).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
. "$ROOT/scripts/lib/cli.sh"
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"
IMAGE=${1:-$ROOT/build/cortex-m4/firmware/ports/cortex-m4/pour_firmware.elf}
OPENOCD=${OPENOCD:-openocd}

fail() { printf 'flash.sh: %s\n' "$2" >&2; exit "$1"; }

[ $# -le 1 ] || fail 2 "usage: scripts/flash.sh [IMAGE.elf]"
[ -f "$IMAGE" ] || fail 2 "no image at $IMAGE: build it with 'cmake --preset cortex-m4 && cmake --build --preset cortex-m4'"
# ELF magic, 32-bit, little-endian, e_machine 40 (ARM): a host binary or a .bin is refused before any probe.
header=$(od -A n -t x1 -N 20 "$IMAGE" | tr -d ' \n')
[ "${header:0:8}" = 7f454c46 ] || fail 2 "$IMAGE is not an ELF file (flash the .elf, not the .bin or .hex)"
[ "${header:8:4}" = 0101 ] && [ "${header:36:4}" = 2800 ] || fail 2 "$IMAGE is not a 32-bit ARM image"
command -v "$OPENOCD" >/dev/null || fail 2 "openocd not found: run scripts/setup.sh (Debian package openocd)"

log=$(mktemp)
trap 'rm -f "$log"' EXIT
if "$OPENOCD" -f interface/stlink.cfg -f target/stm32g4x.cfg -c "program $IMAGE verify reset exit" >"$log" 2>&1; then
  grep -E 'Verified OK|wrote' "$log" >&2 || true
  echo "flash.sh: $IMAGE flashed, verified and the MCU reset" >&2
  exit 0
fi
if grep -qE 'open failed|unable to find|No ST-LINK|LIBUSB_ERROR' "$log"; then
  fail 3 "no ST-LINK probe found: connect the B-G431B-ESC1's USB (ST-LINK side) and check 'lsusb' for 0483:374b"
fi
cat "$log" >&2
fail 1 "openocd failed (output above)"
