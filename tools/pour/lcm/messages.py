# SPDX-License-Identifier: MIT
"""Finds the generated Python LCM types (package ``pour_lcm.pour``): in an installed wheel's data, else in
the build tree CMake generates them into (pour.paths.lcmtypes_python_dirs)."""
from __future__ import annotations

import importlib
import sys
from types import ModuleType

from pour import paths


def load() -> ModuleType:
    """Imports and returns the ``pour_lcm.pour`` package; SystemExit with a hint if it was not built."""
    for folder in paths.lcmtypes_python_dirs():
        if (folder / "pour_lcm" / "pour" / "__init__.py").is_file():
            if str(folder) not in sys.path:
                sys.path.insert(0, str(folder))
            return importlib.import_module("pour_lcm.pour")
    tried = ", ".join(str(c) for c in paths.lcmtypes_python_dirs())
    raise SystemExit(f"error: generated LCM types not found (tried {tried}); build first "
                     "(./scripts/build.sh), install the package from its wheel, or set POUR_LCMTYPES_PYTHON")
