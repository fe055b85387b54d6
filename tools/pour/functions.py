# SPDX-License-Identifier: MIT
"""libpoursim's functions with their argument and return types, declared at load time from the library's own
function table (poursim_function_info, host_sim/include/poursim/function_table.h: each function's declaration
as the compiler sees it). Nothing here restates a signature: a parameter added, removed or retyped in a header
is declared as the header says, and a function the table does not name cannot be called (SimError).

    from pour import functions
    lib = functions.library()          # the declared functions as attributes
    lib.poursim_version().decode()
"""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass
from typing import Any, Iterable

from pour import libpoursim, records
from pour.libpoursim import SimError

_KINDS: dict[str, type] = {**records.SCALARS, "ptr": C.c_void_p}   # "ptr": an opaque handle, an untyped buffer


@dataclass(frozen=True)
class Signature:
    """One row of the library's table: the function's name, its return kind and its parameters' kinds."""
    name: str
    returns: str
    params: tuple[str, ...]


def library_table() -> list[Signature]:
    """Every row of libpoursim's table (poursim_function_info: the one signature written here, to read it)."""
    fn = libpoursim.load().poursim_function_info
    T = C.c_char_p
    fn.argtypes, fn.restype = [C.c_int, C.POINTER(T), C.POINTER(T), C.POINTER(T)], C.c_int
    rows: list[Signature] = []
    name, returns, params = T(), T(), T()
    while fn(len(rows), C.byref(name), C.byref(returns), C.byref(params)) == 0:
        text = params.value.decode()
        rows.append(Signature(name.value.decode(), returns.value.decode(), tuple(text.split(",")) if text else ()))
    return rows


def ctype(kind: str, record_types: dict[str, type]) -> Any:
    """The ctypes type of one kind: a scalar, "ptr" (c_void_p), "void" (None), a record of the record table by
    value, or "<kind>*" a pointer to one of those; SimError for a kind this does not know."""
    if kind == "void":
        return None
    if kind in _KINDS:
        return _KINDS[kind]
    if kind in record_types:
        return record_types[kind]
    if kind.endswith("*") and kind[:-1] not in ("void", "ptr"):
        return C.POINTER(ctype(kind[:-1], record_types))
    raise SimError(f"libpoursim's function table names a kind {kind!r} that pour.functions does not know")


class MissingFunction(SimError, AttributeError):
    """A function libpoursim's table does not name (an AttributeError too, so hasattr() answers False)."""


class Functions:
    """The declared functions of one library, as attributes; path is the library's file."""

    def __init__(self, lib: C.CDLL, rows: Iterable[Signature], record_types: dict[str, type]):
        self.path = lib._name
        self.names: list[str] = []
        for r in rows:
            fn = getattr(lib, r.name)
            fn.argtypes = [ctype(k, record_types) for k in r.params]
            fn.restype = ctype(r.returns, record_types)
            setattr(self, r.name, fn)
            self.names.append(r.name)

    def __getattr__(self, name: str) -> Any:   # only for names that are not declared
        if name.startswith("__"):
            raise AttributeError(name)
        raise MissingFunction(f"libpoursim's function table has no {name!r}: list it in "
                              "host_sim/bridge/function_table.cpp")


_functions: Functions | None = None


def library() -> Functions:
    """libpoursim's functions, declared once from its table (SimError without the library or the table)."""
    global _functions
    if _functions is None:
        lib = libpoursim.load()
        try:
            rows = library_table()
        except AttributeError as e:
            raise SimError(f"libpoursim at {lib._name} does not export its function table (missing symbol: {e})") \
                from e
        _functions = Functions(lib, rows, records.records())
    return _functions


def _name(fn_name: str, value: int) -> str | None:
    name = getattr(library(), fn_name)(value)
    return name.decode() if name is not None else None


def fault_name(bit: int) -> str | None:
    """The firmware core's name of one POUR_FAULT_* bit ("STALE_INPUT", ...; pour_fault_name), None for
    anything else."""
    return _name("pour_fault_name", int(bit) & 0xFFFF)


def fault_names(faults: int) -> list[str]:
    """The names of the bits set in a fault word, lowest bit first (bits the core does not name are left out)."""
    return [n for n in (fault_name(1 << i) for i in range(16) if faults >> i & 1) if n is not None]


def mode_name(mode: int) -> str | None:
    """The firmware core's name of a mode ("IDLE", "RUN", "FAULT", "ESTOP"; pour_mode_name), None outside."""
    return _name("pour_mode_name", int(mode) & 0xFF)
