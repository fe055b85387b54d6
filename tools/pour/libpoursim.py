# SPDX-License-Identifier: MIT
"""libpoursim.so, opened once for the whole package.

One shared library holds the simulator (its entry points declared by pour.sim.poursim) and the firmware core
(declared by pour.core), so both bindings open it here and neither imports the other. pour.paths says
where it is looked for.
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


def _name(fn_name: str, value: int, ctype: type) -> str | None:
    fn = getattr(load(), fn_name)
    fn.argtypes, fn.restype = [ctype], C.c_char_p
    name = fn(value)
    return name.decode() if name is not None else None


def fault_name(bit: int) -> str | None:
    """The firmware core's name of one POUR_FAULT_* bit ("STALE_INPUT", ...; pour_fault_name), None for
    anything else."""
    return _name("pour_fault_name", int(bit) & 0xFFFF, C.c_uint16)


def fault_names(faults: int) -> list[str]:
    """The names of the bits set in a fault word, lowest bit first (bits the core does not name are left out)."""
    return [n for n in (fault_name(1 << i) for i in range(16) if faults >> i & 1) if n is not None]


def mode_name(mode: int) -> str | None:
    """The firmware core's name of a mode ("IDLE", "RUN", "FAULT", "ESTOP"; pour_mode_name), None outside."""
    return _name("pour_mode_name", int(mode) & 0xFF, C.c_uint8)
