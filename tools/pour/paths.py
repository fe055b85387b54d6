# SPDX-License-Identifier: MIT
"""Where the source tree and the CMake build tree are: the one place the package looks for what CMake built
(libpoursim, host_sim and the other programs, the generated LCM types).

A build tree is looked for, in order, at an explicit --build-dir, at $POUR_BUILD_DIR (ctest sets it), then
at <source>/build/host (the `host` preset), then, for callers that accept any preset, at the other
<source>/build/* folders. libpoursim alone can also be named directly with $POUR_SIM_LIB (Ray workers, a
library built elsewhere).

Data that has its one source in the checkout (the DBC, the generated LCM Python types) is found through
data_file() and lcmtypes_python_dirs(): first in the package's own data/ folder, which a wheel carries
(tools/CMakeLists.txt copies and generates it at build time), then in the checkout and its build trees. Nothing
here imports the rest of the package.
"""
from __future__ import annotations

import glob
import os
from pathlib import Path

# The checkout this package lives in (tools/pour/paths.py -> the repository root); an installed copy's
# "source dir" holds no build tree, so only $POUR_BUILD_DIR / $POUR_SIM_LIB / --build-dir find one there.
SOURCE_DIR = Path(__file__).resolve().parents[2]
SIM_LIB_REL = Path("lib") / "libpoursim.so"
# The package's data folder: filled in a built wheel, absent from a checkout (nothing there is a copy).
PACKAGE_DATA = Path(__file__).resolve().parent / "data"
# Each data file a wheel ships, by its name in PACKAGE_DATA, and the one source it is copied from.
DATA_SOURCES = {"pour.dbc": Path("can") / "pour.dbc", "randomised.cfg": Path("configs") / "sim" / "randomised.cfg"}
LCMTYPES_DIR = "lcmtypes"  # PACKAGE_DATA/lcmtypes/pour_lcm/pour/*.py in a wheel
# The package's own libpoursim: a wheel's (tools/CMakeLists.txt builds it), absent from a checkout.
PACKAGE_LIB = Path(__file__).resolve().parent / "lib" / "libpoursim.so"


def build_dirs(build_dir: str | os.PathLike | None = None, any_preset: bool = False) -> list[Path]:
    """Build trees to search, in order: build_dir, $POUR_BUILD_DIR, <source>/build/host, then (any_preset)
    the other <source>/build/* folders, sorted."""
    out: list[Path] = [Path(build_dir)] if build_dir else []
    if os.environ.get("POUR_BUILD_DIR"):
        out.append(Path(os.environ["POUR_BUILD_DIR"]))
    host = SOURCE_DIR / "build" / "host"
    if host not in out:
        out.append(host)
    if any_preset:
        out += [p for p in map(Path, sorted(glob.glob(str(SOURCE_DIR / "build" / "*")))) if p not in out]
    return out


def candidates(rel: str | os.PathLike, build_dir: str | os.PathLike | None = None,
               any_preset: bool = False) -> list[Path]:
    """rel (a path inside a build tree, e.g. "bin/host_sim") under each of build_dirs(), in order."""
    return [d / rel for d in build_dirs(build_dir, any_preset)]


def find(rel: str | os.PathLike, build_dir: str | os.PathLike | None = None, any_preset: bool = False,
         kind: str = "file") -> Path | None:
    """The first of candidates() that exists (kind "file", "dir" or "exe": an executable file), else None."""
    for p in candidates(rel, build_dir, any_preset):
        if kind == "dir" and p.is_dir():
            return p
        if kind == "file" and p.is_file():
            return p
        if kind == "exe" and p.is_file() and os.access(p, os.X_OK):
            return p
    return None


def binary(name: str, build_dir: str | os.PathLike | None = None) -> Path | None:
    """The program NAME in a build tree's bin/, or None."""
    return find(Path("bin") / name, build_dir, kind="exe")


def sim_library_candidates() -> list[Path]:
    """Where libpoursim is looked for, in order: $POUR_SIM_LIB alone when it is set, else the package's own
    (a wheel's), then lib/libpoursim.so of every build tree (any preset)."""
    if os.environ.get("POUR_SIM_LIB"):
        return [Path(os.environ["POUR_SIM_LIB"])]
    return [PACKAGE_LIB] + candidates(SIM_LIB_REL, any_preset=True)


def data_file(name: str) -> Path:
    """The data file NAME (a key of DATA_SOURCES): the package's copy, else the checkout's source.
    FileNotFoundError naming every place tried otherwise."""
    tried = [PACKAGE_DATA / name, SOURCE_DIR / DATA_SOURCES[name]]
    for p in tried:
        if p.is_file():
            return p
    raise FileNotFoundError(f"{name} not found (tried {', '.join(map(str, tried))}): reinstall the package "
                            "from its wheel or run from a checkout")


def lcmtypes_python_dirs() -> list[Path]:
    """Folders that may hold the generated Python LCM types (pour_lcm/pour/*.py), in the order tried:
    $POUR_LCMTYPES_PYTHON, the package's data, then lcmtypes/python of every build tree."""
    out = [Path(os.environ["POUR_LCMTYPES_PYTHON"])] if os.environ.get("POUR_LCMTYPES_PYTHON") else []
    return out + [PACKAGE_DATA / LCMTYPES_DIR] + candidates(Path("lcmtypes") / "python")
