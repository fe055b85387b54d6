# SPDX-License-Identifier: MIT
"""libpoursim.so, opened once for the whole package.

One shared library holds the simulator (pour.sim.poursim) and the firmware core (pour.core), so both bindings
open it here and neither imports the other; its records and its functions are declared from its own tables
(pour.records, pour.functions). pour.paths says where it is looked for.
"""
from __future__ import annotations

import ctypes as C
from pathlib import Path

from pour import paths


class SimError(RuntimeError):
    """libpoursim is missing, failed to load, or refused a call; key names the config key it refused, if any."""

    def __init__(self, message: str, key: str | None = None):
        super().__init__(message)
        self.key = key


_lib: C.CDLL | None = None


def candidates() -> list[Path]:
    """Where load() looks, in order ($POUR_SIM_LIB alone when it is set)."""
    return paths.sim_library_candidates()


def load() -> C.CDLL:
    """The library, opened on the first call (no entry point declared); SimError says where it looked."""
    global _lib
    if _lib is not None:
        return _lib
    tried = candidates()
    for path in tried:
        if path.is_file():
            try:
                _lib = C.CDLL(str(path))
            except OSError as e:
                raise SimError(f"libpoursim at {path} failed to load: {e}") from e
            return _lib
    raise SimError("libpoursim.so not found (looked at: " + ", ".join(map(str, tried)) +
                   "); reinstall the package from a checkout (pip install ./tools builds it in), build it with "
                   "`cmake --workflow --preset host`, or set POUR_SIM_LIB")
