# SPDX-License-Identifier: MIT
"""pour-virtual-board: the flashed image on the virtual B-G431B-ESC1 (docs/virtual-board.md).

Finds pour_virtual_board in the build tree (pour.paths: --build-dir, $POUR_BUILD_DIR, build/host) and runs it
with the remaining arguments; without --elf, the image scripts/flash.sh flashes
(<source>/build/cortex-m4/firmware/ports/cortex-m4/pour_firmware.elf). Its options: pour-virtual-board --help.
"""
from __future__ import annotations

import os
import sys

from pour import cli, paths

ELF = paths.SOURCE_DIR / "build" / "cortex-m4" / "firmware" / "ports" / "cortex-m4" / "pour_firmware.elf"


USAGE = """usage: pour-virtual-board [--build-dir DIR] [OPTIONS of pour_virtual_board]

Runs the flashed image (scripts/flash.sh's pour_firmware.elf, or --elf FILE) on the virtual B-G431B-ESC1:
an emulated STM32G431 with models of its peripherals, the board's analog chain and the motor
(docs/virtual-board.md). It runs pour_virtual_board from the build tree (--build-dir, $POUR_BUILD_DIR or
build/host); that program's own options (--channel, --seconds, --until-heartbeat, ...) are listed by
pour-virtual-board --help once it is built (cmake --preset host && cmake --build --preset host).
"""


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if "--version" in args:
        print(f"pour-virtual-board {cli.version()}")
        return 0
    build_dir = None
    if "--build-dir" in args:
        i = args.index("--build-dir")
        if i + 1 >= len(args):
            print("pour-virtual-board: --build-dir needs a folder", file=sys.stderr)
            return 2
        build_dir = args[i + 1]
        del args[i:i + 2]
    exe = paths.binary("pour_virtual_board", build_dir)
    if exe is None and ("--help" in args or "-h" in args):
        print(USAGE, end="")
        return 0
    if exe is None:
        dirs = ", ".join(map(str, paths.build_dirs(build_dir)))
        print(f"pour-virtual-board: pour_virtual_board not found under {dirs}; build it first "
              "(cmake --preset host && cmake --build --preset host)", file=sys.stderr)
        return 2
    if "--help" in args or "-h" in args:
        print(USAGE)
        sys.stdout.flush()
    elif "--elf" not in args:
        args = ["--elf", str(ELF), *args]
    sys.stdout.flush()
    os.execv(exe, [str(exe), *args])
    return 0  # not reached


if __name__ == "__main__":
    sys.exit(main())
