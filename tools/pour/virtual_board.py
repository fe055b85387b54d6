# SPDX-License-Identifier: MIT
"""pour-virtual-board: the flashed image on the virtual B-G431B-ESC1 (docs/virtual-board.md).

Finds pour_virtual_board in the build tree (pour.paths: --build-dir, $POUR_BUILD_DIR, build/host) and runs it
with the remaining arguments; without --elf, the image scripts/flash.sh flashes
(<source>/build/cortex-m4/firmware/ports/cortex-m4/pour_firmware.elf). Its options: pour-virtual-board --help.
"""
from __future__ import annotations

import os
import sys

from pour import paths

ELF = paths.SOURCE_DIR / "build" / "cortex-m4" / "firmware" / "ports" / "cortex-m4" / "pour_firmware.elf"


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    build_dir = None
    if "--build-dir" in args:
        i = args.index("--build-dir")
        if i + 1 >= len(args):
            print("pour-virtual-board: --build-dir needs a folder", file=sys.stderr)
            return 2
        build_dir = args[i + 1]
        del args[i:i + 2]
    exe = paths.binary("pour_virtual_board", build_dir)
    if exe is None:
        dirs = ", ".join(map(str, paths.build_dirs(build_dir)))
        print(f"pour-virtual-board: pour_virtual_board not found under {dirs}; build it first "
              "(cmake --preset host && cmake --build --preset host)", file=sys.stderr)
        return 2
    if "--elf" not in args and "--help" not in args and "-h" not in args:
        args = ["--elf", str(ELF), *args]
    sys.stdout.flush()
    os.execv(exe, [str(exe), *args])
    return 0  # not reached


if __name__ == "__main__":
    sys.exit(main())
