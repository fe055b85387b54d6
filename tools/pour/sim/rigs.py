# SPDX-License-Identifier: MIT
"""Named rig distributions: configs/sim/<name>.cfg, in the simulator's config format ("key = value", '#'
comments; configs/sim/default.cfg's). The training distribution is configs/sim/randomised.cfg, named by
the training configs ([env] rig = "randomised"), the Gymnasium id pour/PourRandomised-v0 and
pour-robust-scale; its widths are written nowhere else (tests/python/test_rigs.py).

    from pour.sim import rigs
    rigs.load("randomised")   # {"rand_fill": ..., "rand_target_dx": ..., ...}
"""
from __future__ import annotations

import math

from pour import paths

# Rig names -> their file (pour.paths.DATA_SOURCES carries each into a wheel).
RIGS = {"randomised": "randomised.cfg"}


class RigError(ValueError):
    """A rig name that is not declared, or a rig file that does not read."""


def names() -> tuple[str, ...]:
    return tuple(RIGS)


def load(name: str) -> dict[str, float]:
    """The keys of rig NAME and their values, in the file's order; RigError names a bad line."""
    if name not in RIGS:
        raise RigError(f"unknown rig {name!r}: expected one of {', '.join(RIGS)}")
    try:
        path = paths.data_file(RIGS[name])
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise RigError(f"rig {name!r}: {e}") from None
    out: dict[str, float] = {}
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        key, sep, value = (s.strip() for s in line.partition("="))
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        if not sep or not key or not math.isfinite(v) or key in out:
            raise RigError(f"{path}:{n}: expected one 'key = number' per key, got {raw.strip()!r}")
        out[key] = v
    if not out:
        raise RigError(f"{path}: no keys")
    return out
