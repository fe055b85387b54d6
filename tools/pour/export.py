# SPDX-License-Identifier: MIT
"""pour-export: a training run's policy.json -> weights.h (docs/weights-h.md), through pour.weights_h.

The banner carries the sha256 of policy.json, whose bytes are a deterministic function of the
training config, so exporting twice (or re-training and exporting) gives byte-identical headers.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import fixedpoint as fp
from pour import weights_h


class ExportError(ValueError):
    """A policy.json that cannot be exported."""


def load_policy(path: str | Path) -> dict[str, Any]:
    """Reads a run's policy.json (or the run directory holding it) and checks its fields."""
    path = Path(path)
    if path.is_dir():
        path = path / "policy.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ExportError(f"{path}: cannot read ({exc.strerror})") from exc
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ExportError(f"{path}: not valid JSON ({exc})") from exc
    if not isinstance(doc, dict) or doc.get("format") != "pour-policy-1":
        raise ExportError(f"{path}: not a pour policy file (format 'pour-policy-1' expected)")
    for key in ("n_actions", "decision_period_ms", "tau_max_nm", "norm", "w", "best_w"):
        if key not in doc:
            raise ExportError(f"{path}: missing field {key!r}")
    doc["_path"] = path
    return doc


def norm_of(doc: dict[str, Any]) -> fp.ObsNorm:
    n = doc["norm"]
    return fp.ObsNorm(int(round(n["theta_min_rad"] * 1e6)), int(round(n["theta_max_rad"] * 1e6)),
                      int(round(n["omega_max_rad_s"] * 1e6)))


def weights_of(doc: dict[str, Any], which: str = "best") -> np.ndarray:
    """The float W [6][n_actions] of the policy file: 'best' (validation-selected) or 'last'."""
    if which not in ("best", "last"):
        raise ExportError(f"which = {which!r}: expected 'best' or 'last'")
    w = np.array(doc["best_w" if which == "best" else "w"], dtype=np.float64)
    if w.shape != (fp.N_FEATURES, int(doc["n_actions"])):
        raise ExportError(f"{doc['_path']}: W has shape {w.shape}, expected ({fp.N_FEATURES}, {doc['n_actions']})")
    if not np.all(np.isfinite(w)):
        raise ExportError(f"{doc['_path']}: W holds NaN or infinity")
    return w


def export(policy: str | Path, out: str | Path, which: str = "best", frac_bits: int | None = None,
           float_reference: bool = True) -> weights_h.WeightsH:
    """Writes weights.h for a run's policy; returns what was written (parsed back)."""
    doc = load_policy(policy)
    w = weights_of(doc, which)
    tau = float(doc["tau_max_nm"])
    if not math.isfinite(tau) or tau <= 0:
        raise ExportError(f"{doc['_path']}: tau_max_nm = {tau}: expected > 0")
    try:
        return weights_h.write_weights_h(out, w, levels=None, frac_bits=frac_bits,
                                         decision_period_ms=int(doc["decision_period_ms"]), norm=norm_of(doc),
                                         tau_max_mnm=int(round(tau * 1000)), banner_inputs=[doc["_path"]],
                                         float_reference=float_reference)
    except weights_h.WeightsHError as exc:
        raise ExportError(str(exc)) from exc


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="pour-export", description=__doc__.split("\n")[0])
    ap.add_argument("run", help="run directory (or its policy.json)")
    ap.add_argument("--out", required=True, help="weights.h to write (e.g. policy/weights.h)")
    ap.add_argument("--which", default="best", choices=("best", "last"),
                    help="best: the weights with the best greedy validation score (default); last: the final ones")
    ap.add_argument("--frac-bits", type=int, help="fraction bits of W (default: the most that fit)")
    args = ap.parse_args(argv)
    try:
        res = export(args.run, args.out, args.which, args.frac_bits)
    except ExportError as exc:
        print(f"pour-export: error: {exc}", file=sys.stderr)
        return 2
    print(f"pour-export: wrote {args.out} ({res.n_actions} actions, Q{15 - res.w_frac_bits}.{res.w_frac_bits}, "
          f"hash 0x{res.content_hash:08x})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
