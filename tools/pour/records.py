# SPDX-License-Identifier: MIT
"""The ctypes classes of the records that cross libpoursim's C API, built at load time from the library's own
layout table (poursim_record_field, host_sim/include/poursim/record_layouts.h: offsetof and sizeof, as the
compiler laid each record out). Nothing here restates a field: a record reordered or retyped in C is read
right by name, and a layout ctypes cannot reproduce (a member left out of the table, a kind it does not know)
is refused with SimError when the library loads.

    from pour import records
    Obs = records.record("poursim_obs_t")      # a ctypes.Structure subclass
    o = Obs(); o.theta
"""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass
from typing import Iterable

from pour import libpoursim
from pour.libpoursim import SimError

SCALARS: dict[str, type] = {   # the tables' scalar kinds (pour.functions reads them too)
    "i8": C.c_int8, "u8": C.c_uint8, "i16": C.c_int16, "u16": C.c_uint16, "i32": C.c_int32, "u32": C.c_uint32,
    "i64": C.c_int64, "u64": C.c_uint64, "f32": C.c_float, "f64": C.c_double, "bool": C.c_bool, "cstr": C.c_char_p,
}


@dataclass(frozen=True)
class FieldLayout:
    """One row of the library's table."""
    record: str
    record_size: int
    record_align: int
    field: str
    offset: int
    size: int
    kind: str
    count: int


class _Record(C.Structure):
    def __repr__(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(f"{k}={getattr(self, k)!r}" for k, *_ in self._fields_) + ")"


def library_table() -> list[FieldLayout]:
    """Every row of libpoursim's table (poursim_record_field_info, plain out-parameters)."""
    fn = libpoursim.load().poursim_record_field_info
    P, S, T = C.POINTER, C.c_size_t, C.c_char_p
    fn.argtypes, fn.restype = [C.c_int, P(T), P(S), P(S), P(T), P(S), P(S), P(T), P(S)], C.c_int
    rows: list[FieldLayout] = []
    rec, field, kind = T(), T(), T()
    rsize, ralign, off, size, count = S(), S(), S(), S(), S()
    while fn(len(rows), C.byref(rec), C.byref(rsize), C.byref(ralign), C.byref(field), C.byref(off),
             C.byref(size), C.byref(kind), C.byref(count)) == 0:
        rows.append(FieldLayout(rec.value.decode(), rsize.value, ralign.value, field.value.decode(), off.value,
                                size.value, kind.value.decode(), count.value))
    return rows


def _ctype(kind: str, built: dict[str, type]) -> type:
    if kind in SCALARS:
        return SCALARS[kind]
    if kind.endswith("*") and kind[:-1] in SCALARS:
        return C.POINTER(SCALARS[kind[:-1]])
    if kind in built:
        return built[kind]
    raise SimError(f"libpoursim's record table names a field kind {kind!r} that pour.records does not know")


def build(rows: Iterable[FieldLayout]) -> dict[str, type]:
    """ctypes classes from table rows, by C name; each class's offsets and size are checked against the
    rows (SimError names the record and the field that ctypes lays out differently, or the gap a member left
    out of the table leaves)."""
    by_record: dict[str, list[FieldLayout]] = {}
    for r in rows:
        by_record.setdefault(r.record, []).append(r)
    built: dict[str, type] = {}
    for name, fields in by_record.items():
        fields = sorted(fields, key=lambda f: f.offset)
        spec, end = [], 0
        for f in fields:
            t = _ctype(f.kind, built)
            if C.sizeof(t) != f.size:
                raise SimError(f"record {name}.{f.field}: kind {f.kind} is {C.sizeof(t)} bytes in ctypes, "
                               f"{f.size} in C")
            if f.offset - end >= max(C.alignment(t), 1) or f.offset < end:
                raise SimError(f"record {name}: bytes {end}..{f.offset} before {f.field} are not in the table "
                               "(a member left out?)")
            spec.append((f.field, t * f.count if f.count != 1 else t))
            end = f.offset + f.size * f.count
        if fields[0].record_size - end >= fields[0].record_align:
            raise SimError(f"record {name}: bytes {end}..{fields[0].record_size} at its end are not in the table "
                           "(a member left out?)")
        cls = type(name, (_Record,), {"_fields_": spec, "__doc__": f"{name}, laid out by libpoursim's table."})
        for f in fields:
            if getattr(cls, f.field).offset != f.offset:
                raise SimError(f"record {name}.{f.field}: ctypes puts it at {getattr(cls, f.field).offset}, "
                               f"C at {f.offset}")
        if C.sizeof(cls) != fields[0].record_size:
            raise SimError(f"record {name}: {C.sizeof(cls)} bytes in ctypes, {fields[0].record_size} in C")
        built[name] = cls
    return built


_records: dict[str, type] | None = None


def records() -> dict[str, type]:
    """Every record of libpoursim's table, built once."""
    global _records
    if _records is None:
        try:
            _records = build(library_table())
        except AttributeError as e:
            raise SimError(f"libpoursim does not export its record table (missing symbol: {e})") from e
    return _records


def record(name: str) -> type:
    """The ctypes class of one record by its C name (poursim_obs_t, pour_control_output_t, ...)."""
    table = records()
    if name not in table:
        raise SimError(f"libpoursim's record table has no {name!r} (it has {', '.join(sorted(table))})")
    return table[name]
