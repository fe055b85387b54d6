# SPDX-License-Identifier: MIT
"""The controller's parameters in SI units, for pour-bench config: each parameter's unit, default and range come
from the firmware's own table (POUR_PARAMS in firmware/include/pour/params.h, read through libpoursim's
pour_param_info; no list is kept here), the value on the bus is that unit's integer, and SI maps each firmware
unit to its SI one.
A dump is a JSON file of every parameter's raw value with its SI reading; a restore checks the whole file
against the table before it writes anything."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pour import atomic, functions

# Firmware unit -> (SI unit, SI per firmware unit). Q15 torques are fractions of the node's full-scale torque
# (Identity.TauMax), named as such.
SI: dict[str, tuple[str, float]] = {
    "Q15": ("of tau_max", 1.0 / 32768.0),
    "Q15/(rad/s)": ("tau_max/(rad/s)", 1.0 / 32768.0),
    "urad": ("rad", 1e-6),
    "urad/s": ("rad/s", 1e-6),
    "urad/s2": ("rad/s^2", 1e-6),
    "ms": ("s", 1e-3),
    "1/1000": ("", 1e-3),
    "ppm": ("", 1e-6),
    "g": ("kg", 1e-3),
    "1/s": ("1/s", 1.0),
    "bits": ("bits", 1.0),
    "counts": ("counts", 1.0),
    "": ("", 1.0),
}

DUMP_FORMAT = "pour-bench config dump 1"


class ParamFileError(ValueError):
    """A dump file that cannot be read, or whose content the table refuses."""


@dataclass(frozen=True)
class Param:
    """One row of the firmware's parameter table."""
    id: int
    name: str
    unit: str   # the firmware's (the bus value's)
    min: int    # raw, inclusive
    max: int
    default: int  # raw, as compiled (the node id the port's own)

    @property
    def si_unit(self) -> str:
        return SI.get(self.unit, (self.unit, 1.0))[0]

    @property
    def scale(self) -> float:
        return SI.get(self.unit, (self.unit, 1.0))[1]

    def to_si(self, raw: int) -> float:
        return raw * self.scale

    def from_si(self, value: float) -> int:
        """The raw value nearest to value [SI]; ValueError naming the range when it lies outside."""
        if not math.isfinite(value):
            raise ValueError(f"{self.name}: {value} is not a number")
        raw = round(value / self.scale)
        if not self.min <= raw <= self.max:
            raise ValueError(f"{self.name} = {value:g} {self.si_unit}".rstrip() + f" is outside {self.range_text()}")
        return raw

    def check_raw(self, raw: int) -> int:
        if not self.min <= raw <= self.max:
            raise ValueError(f"{self.name} = {raw} {self.unit}".rstrip() + f" is outside {self.min} .. {self.max}")
        return raw

    def range_text(self) -> str:
        return f"{self.to_si(self.min):.6g} .. {self.to_si(self.max):.6g} {self.si_unit}".rstrip()

    def describe(self, raw: int) -> str:
        """`omega_max 1.5 rad/s (range 1e-06 .. 2 rad/s; default 2 rad/s; raw 1500000 urad/s)`."""
        si = f"{self.to_si(raw):.6g} {self.si_unit}".rstrip()
        default = f"{self.to_si(self.default):.6g} {self.si_unit}".rstrip()
        return (f"{self.name} {si} (range {self.range_text()}; default {default}; "
                f"raw {raw} {self.unit})").replace(" )", ")")


def table() -> dict[str, Param]:
    """Every parameter of the firmware's table, by name, in id order (SimError without libpoursim)."""
    fn = functions.library().pour_param_info
    out: dict[str, Param] = {}
    for pid in range(256):
        row = fn(pid)
        if row:
            r = row.contents
            out[r.name.decode()] = Param(int(r.id), r.name.decode(), r.unit.decode(), int(r.min), int(r.max),
                                          int(r.default_value))
    return out


def dump(path: Path, node_id: int, raw: dict[str, int], params: dict[str, Param]) -> None:
    """Writes every parameter's raw value and SI reading as JSON (through a temp file, renamed)."""
    doc = {"format": DUMP_FORMAT, "node": node_id, "params": {
        name: {"raw": v, "unit": params[name].unit, "value": params[name].to_si(v), "si_unit": params[name].si_unit}
        for name, v in raw.items()}}
    with atomic.atomic_path(path) as tmp:
        Path(tmp).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def load_dump(path: Path, params: dict[str, Param]) -> dict[str, int]:
    """The raw values of a dump, every one checked against the table; ParamFileError says what is wrong."""
    try:
        doc: Any = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as e:
        raise ParamFileError(f"{path}: cannot read ({e.strerror})") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ParamFileError(f"{path}: not a config dump ({e})") from None
    if not isinstance(doc, dict) or doc.get("format") != DUMP_FORMAT or not isinstance(doc.get("params"), dict):
        raise ParamFileError(f"{path}: not a config dump (no \"format\": \"{DUMP_FORMAT}\" with \"params\")")
    out: dict[str, int] = {}
    for name, entry in doc["params"].items():
        if name not in params:
            raise ParamFileError(f"{path}: no parameter '{name}' in this firmware's table")
        raw = entry.get("raw") if isinstance(entry, dict) else None
        if not isinstance(raw, int) or isinstance(raw, bool):
            raise ParamFileError(f"{path}: {name}: no integer \"raw\" value")
        if isinstance(entry, dict) and entry.get("unit", params[name].unit) != params[name].unit:
            raise ParamFileError(f"{path}: {name} is in {entry['unit']!r}, this firmware's in {params[name].unit!r}")
        try:
            out[name] = params[name].check_raw(raw)
        except ValueError as e:
            raise ParamFileError(f"{path}: {e}") from None
    if not out:
        raise ParamFileError(f"{path}: no parameters")
    return out
