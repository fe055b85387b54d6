# SPDX-License-Identifier: MIT
"""Finds the Python LCM types that CMake generates into the build tree (package ``pour_lcm.pour``)."""
from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from types import ModuleType

from pour import paths


def candidates() -> list[Path]:
    """Folders that may hold ``pour_lcm/pour/*.py``, in the order they are tried."""
    out = []
    if os.environ.get("POUR_LCMTYPES_PYTHON"):
        out.append(Path(os.environ["POUR_LCMTYPES_PYTHON"]))
    return out + paths.candidates(Path("lcmtypes") / "python")


def load() -> ModuleType:
    """Imports and returns the ``pour_lcm.pour`` package; SystemExit with a hint if it was not built."""
    for folder in candidates():
        if (folder / "pour_lcm" / "pour" / "__init__.py").is_file():
            if str(folder) not in sys.path:
                sys.path.insert(0, str(folder))
            return importlib.import_module("pour_lcm.pour")
    tried = ", ".join(str(c) for c in candidates())
    raise SystemExit(f"error: generated LCM types not found (tried {tried}); build first "
                     "(cmake --workflow --preset host) or set POUR_LCMTYPES_PYTHON")
