# SPDX-License-Identifier: MIT
"""Rig files: the simulator's keys for one real rig, with the fit's uncertainty of each.

Two formats, by the file's suffix: TOML (`key = value` at the top, and a `[sigma]` table of the standard
deviations in the same units), or the simulator's cfg format (`key = value` lines, host_sim --config;
the uncertainties go in comments there, which nothing reads back). Every key must be one of the
simulator's and within its range: the library that runs the simulator judges both."""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from pour import atomic
from pour.sim import poursim

# The figures pour-sysid fits, in the order it writes them (fill_depth and fluid_viscosity with a tilt log only).
FITTED = ("torque_scale", "motor_rotor_inertia", "friction_coulomb", "friction_viscous", "command_latency_ticks",
          "scale_delay_s", "scale_noise_g", "fill_depth", "fluid_viscosity")


class RigError(ValueError):
    """A rig file that cannot be used, and why."""


@dataclass
class Rig:
    values: dict[str, float] = field(default_factory=dict)  # simulator keys -> values
    sigma: dict[str, float] = field(default_factory=dict)   # the same keys -> standard deviations


def _check(values: dict, where: str) -> None:
    info = poursim.describe()
    for k, v in values.items():
        if k not in info:
            raise RigError(f"{where}: '{k}' is no simulator key (host_sim --list-config lists them)")
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise RigError(f"{where}: {k} = {v!r} is not a number")
    try:
        poursim.make_config(values)
    except poursim.SimError as e:
        raise RigError(f"{where}: {e}") from e


def load(path: Path) -> Rig:
    """A rig file (TOML, or the simulator's cfg format), every key and value checked."""
    if path.suffix == ".toml":
        try:
            doc = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as e:
            raise RigError(f"{path}: {e}") from e
        sigma = doc.pop("sigma", {})
        if not isinstance(sigma, dict):
            raise RigError(f"{path}: 'sigma' must be a table of standard deviations")
        _check(doc, str(path))
        for k, v in sigma.items():
            if k not in doc:
                raise RigError(f"{path}: [sigma] {k} has no value in the rig file")
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not v >= 0 or math.isinf(v):
                raise RigError(f"{path}: [sigma] {k} = {v!r} is not a standard deviation (a number >= 0)")
        return Rig({k: float(v) for k, v in doc.items()}, {k: float(v) for k, v in sigma.items()})
    try:
        cfg = poursim.make_config(path=path)
    except poursim.SimError as e:
        raise RigError(f"{path}: {e}") from e
    except OSError as e:
        raise RigError(f"{path}: {e}") from e
    defaults = poursim.default_config()
    return Rig({k: float(v) for k, v in cfg.as_dict().items() if v != defaults[k]})


def _num(k: str, v: float) -> str:
    return str(int(round(v))) if poursim.describe()[k].integer else f"{v:.9g}"


def save(path: Path, rig: Rig, header: list[str]) -> None:
    """Writes rig atomically in the format of path's suffix; header: comment lines (no '#')."""
    _check(rig.values, str(path))
    lines = [f"# {h}" for h in header]
    if path.suffix == ".toml":
        lines += [f"{k} = {_num(k, v)}" for k, v in rig.values.items()]
        if rig.sigma:
            lines += ["", "[sigma]  # standard deviations, in the keys' units"]
            lines += [f"{k} = {v:.9g}" for k, v in rig.sigma.items()]
    else:
        for k, v in rig.values.items():
            s = rig.sigma.get(k)
            lines.append(f"{k} = {_num(k, v)}" + (f"  # sigma {s:.3g}" if s is not None else ""))
    with atomic.atomic_path(path) as tmp:
        Path(tmp).write_text("\n".join(lines) + "\n")


# The simulator's randomisation keys that spread each fitted figure (config_fields.h, "domain randomisation").
SPREAD = {"motor_rotor_inertia": "rand_motor", "friction_coulomb": "rand_motor", "friction_viscous": "rand_motor",
          "scale_delay_s": "rand_sensor", "scale_noise_g": "rand_sensor", "fill_depth": "rand_fill"}


def centred(options: dict, rig: Rig) -> dict:
    """Simulator options with rig's values as the nominal and each randomisation width set by the fit: a
    uniform spread of half-width √3 σ (the same standard deviation) relative to the value, the widest of the
    figures one key spreads; keys with no σ keep the options' width."""
    out = {**options, **rig.values}
    info = poursim.describe()
    widths: dict[str, float] = {}
    for k, key in SPREAD.items():
        v, s = rig.values.get(k), rig.sigma.get(k)
        if v and s is not None:
            widths[key] = max(widths.get(key, 0.0), min(info[key].max, math.sqrt(3.0) * s / abs(v)))
    out.update(widths)
    return out


def host_sim_sets(rig: Rig) -> list[str]:
    """rig's values as host_sim --set arguments."""
    return [a for k, v in rig.values.items() for a in ("--set", f"{k}={_num(k, v)}")]
