# SPDX-License-Identifier: MIT
"""The records that cross libpoursim's C API are built from the library's own layout table (pour.records):
none is written by hand in tools/, each matches the compiler's offsets and sizes, and a reorder or a left-out
member in C is read right or refused, never misread."""
from __future__ import annotations

import ast
import ctypes as C
import struct
from pathlib import Path

import pytest

from pour import core, records
from pour.libpoursim import SimError
from pour.sim import poursim

TOOLS = Path(__file__).resolve().parents[2] / "tools"


@pytest.fixture(autouse=True)
def _lib(build_dir, monkeypatch):
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))


def test_no_ctypes_record_class_is_written_by_hand_in_tools():
    """No class in tools/ derives from ctypes.Structure or Union with its own _fields_: records.py's _Record
    base (no fields) is the only Structure subclass, and the built classes take their fields from the table."""
    hand = []
    for path in sorted(TOOLS.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef):
                bases = {ast.unparse(b) for b in node.bases}
                fields = any(isinstance(s, ast.Assign) and any(ast.unparse(t) == "_fields_" for t in s.targets)
                             for s in node.body)
                if fields or bases & {"C.Structure", "ctypes.Structure", "C.Union", "ctypes.Union", "Structure"}:
                    hand.append(f"{path.relative_to(TOOLS)}:{node.lineno} {node.name}")
    assert len(hand) == 1 and hand[0].startswith("pour/records.py:") and hand[0].endswith(" _Record"), hand


def test_every_record_of_the_table_has_the_library_s_offsets_and_size():
    lib = poursim.load_library()
    rows = records.library_table()
    built = records.records()
    assert {r.record for r in rows} == set(built)
    for r in rows:
        assert getattr(built[r.record], r.field).offset == r.offset, (r.record, r.field)
    for r in rows:
        assert C.sizeof(built[r.record]) == r.record_size, r.record
    known = {name: lib.poursim_sizeof(name.encode()) for name in built}
    assert all(C.sizeof(built[n]) == size for n, size in known.items() if size), known
    assert [n for n, size in known.items() if not size] == ["pour_param_info_t"]  # a table row, not in sizeof


def test_every_record_python_names_is_in_the_table():
    names = set(poursim.RECORDS.values()) | set(core.RECORDS.values())
    names |= {"poursim_weights_file_t", "pour_param_info_t"}
    assert names <= set(records.records())
    assert len(records.records()) == 15  # the nine of the simulator, the core's four, weights.h, a parameter


def test_values_the_library_writes_are_read_by_name():
    """The default reward's fields and a parameter row come back under their own names (a table whose names
    were swapped against their offsets would read 5, 1 here)."""
    r = poursim.default_reward()
    assert (r.k_target, r.k_spill, r.gamma) == (1.0, 5.0, 0.9995)
    from pour.bench import params
    table = params.table()
    omega = table["omega_max"]
    assert omega.unit == "urad/s" and 0 < omega.min < omega.max


def _rows(*fields):
    """A test-only record: (name, offset, kind) with 4-byte int32 members, 12 bytes."""
    return [records.FieldLayout("probe_t", 12, 4, n, off, 4, kind, 1) for n, off, kind in fields]


def test_a_reorder_in_c_is_read_right_by_name():
    declared = records.build(_rows(("a", 0, "i32"), ("b", 4, "i32"), ("c", 8, "u32")))["probe_t"]
    swapped = records.build(_rows(("b", 0, "i32"), ("a", 4, "i32"), ("c", 8, "u32")))["probe_t"]
    as_declared = declared.from_buffer_copy(struct.pack("<iiI", 11, 22, 33))
    assert (as_declared.a, as_declared.b, as_declared.c) == (11, 22, 33)
    # C swapped a and b: the same names now live at the other offsets, and are read there.
    s = swapped.from_buffer_copy(struct.pack("<iiI", 22, 11, 33))
    assert (s.a, s.b, s.c) == (11, 22, 33)
    assert [f for f, _ in swapped._fields_] == ["b", "a", "c"]


def test_a_member_left_out_of_the_table_is_refused_by_name():
    with pytest.raises(SimError, match=r"record probe_t: bytes 4\.\.8 before c are not in the table"):
        records.build(_rows(("a", 0, "i32"), ("c", 8, "u32")))
    with pytest.raises(SimError, match=r"record probe_t: bytes 8\.\.12 at its end"):
        records.build(_rows(("a", 0, "i32"), ("b", 4, "i32")))


def test_a_kind_of_the_wrong_size_or_unknown_is_refused():
    with pytest.raises(SimError, match=r"probe_t\.c: kind f64 is 8 bytes in ctypes, 4 in C"):
        records.build(_rows(("a", 0, "i32"), ("b", 4, "i32"), ("c", 8, "f64")))
    with pytest.raises(SimError, match="kind 'q7' that pour.records does not know"):
        records.build(_rows(("a", 0, "i32"), ("b", 4, "i32"), ("c", 8, "q7")))
