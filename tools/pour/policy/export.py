# SPDX-License-Identifier: MIT
"""pour-export: a training run's policy.json -> weights.h (docs/weights-h.md), through pour.policy.weights_h.

The banner carries the sha256 of policy.json, whose bytes are a deterministic function of the
training config, so exporting twice (or re-training and exporting) gives byte-identical headers.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import atomic, cli
from pour.policy import fixedpoint as fp
from pour.policy import weights_h


class ExportError(ValueError):
    """A policy.json that cannot be exported."""


class ExportWriteError(ExportError):
    """weights.h could not be written (the previous file, if any, is unchanged)."""


def _number(path: Path, name: str, value: Any) -> float:
    """A finite JSON number (not a bool, a string or null)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ExportError(f"{path}: {name} is {json.dumps(value)[:40]}, not a number")
    if not math.isfinite(value):
        raise ExportError(f"{path}: {name} is {value}, not a finite number")
    return float(value)


def _integer(path: Path, name: str, value: Any, lo: int, hi: int) -> int:
    """A whole number in lo..hi (10.0 is 10; 10.9 is refused, not truncated)."""
    v = _number(path, name, value)
    if v != math.floor(v) or not lo <= v <= hi:
        raise ExportError(f"{path}: {name} is {json.dumps(value)}, not an integer in {lo}..{hi}")
    return int(v)


def _matrix(path: Path, name: str, value: Any, n_actions: int) -> np.ndarray:
    """W: [6][n_actions] finite numbers, row by row."""
    if not isinstance(value, list) or len(value) != fp.N_FEATURES:
        got = f"{len(value)} rows" if isinstance(value, list) else json.dumps(value)[:40]
        raise ExportError(f"{path}: {name} has {got}, expected {fp.N_FEATURES} rows of {n_actions}")
    for r, row in enumerate(value):
        if not isinstance(row, list) or len(row) != n_actions:
            got = f"{len(row)} values" if isinstance(row, list) else json.dumps(row)[:40]
            raise ExportError(f"{path}: {name} row {r} has {got}, expected {n_actions} values")
        for c, v in enumerate(row):
            _number(path, f"{name}[{r}][{c}]", v)
    return np.array(value, dtype=np.float64)


POLICY_FORMAT = "pour-policy-1"


def write_policy(path: str | Path, n_actions: int, decision_period_ms: int, tau_max_nm: float,
                 norm: dict[str, float], w: np.ndarray, best_w: np.ndarray, **fields: Any) -> None:
    """Writes a policy.json that load_policy reads (atomically, deterministic bytes: sorted keys, no times):
    the trainer's output and any other learner's (pour.examples.sb3_ppo). norm: theta_min_rad,
    theta_max_rad, omega_max_rad_s; fields: anything else the writer records (config, iteration, ...)."""
    doc = dict(fields, format=POLICY_FORMAT, n_actions=int(n_actions), decision_period_ms=int(decision_period_ms),
               tau_max_nm=float(tau_max_nm), norm=dict(norm), w=np.asarray(w).tolist(),
               best_w=np.asarray(best_w).tolist())
    atomic.write_atomic(path, (json.dumps(doc, indent=1, sort_keys=True) + "\n").encode())


def load_policy(path: str | Path) -> dict[str, Any]:
    """Reads a run's policy.json (or the run directory holding it) and checks every field the export uses:
    one ExportError naming the first bad field. Numbers come back as int/float, W as arrays."""
    path = Path(path)
    if path.is_dir():
        path = path / "policy.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ExportError(f"{path}: cannot read ({exc.strerror})") from exc
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as exc:
        raise ExportError(f"{path}: not valid JSON ({str(exc)[:80]})") from exc
    if not isinstance(doc, dict) or doc.get("format") != POLICY_FORMAT:
        raise ExportError(f"{path}: not a pour policy file (format '{POLICY_FORMAT}' expected)")
    for key in ("n_actions", "decision_period_ms", "tau_max_nm", "norm", "w", "best_w"):
        if key not in doc:
            raise ExportError(f"{path}: missing field {key!r}")
    doc["n_actions"] = _integer(path, "n_actions", doc["n_actions"], fp.MIN_ACTIONS, fp.MAX_ACTIONS)
    doc["decision_period_ms"] = _integer(path, "decision_period_ms", doc["decision_period_ms"], 1, 65535)
    doc["tau_max_nm"] = _number(path, "tau_max_nm", doc["tau_max_nm"])
    if not 0 < doc["tau_max_nm"] * 1000 <= fp.INT32_MAX:
        raise ExportError(f"{path}: tau_max_nm is {doc['tau_max_nm']}, expected > 0 (and < 2.1e6)")
    norm = doc["norm"]
    if not isinstance(norm, dict):
        raise ExportError(f"{path}: norm is {json.dumps(norm)[:40]}, expected an object")
    for key in ("theta_min_rad", "theta_max_rad", "omega_max_rad_s"):
        if key not in norm:
            raise ExportError(f"{path}: missing field 'norm.{key}'")
        norm[key] = _number(path, f"norm.{key}", norm[key])
        if not fp.INT32_MIN <= round(norm[key] * 1e6) <= fp.INT32_MAX:
            raise ExportError(f"{path}: norm.{key} is {norm[key]}, outside int32 in micro-units")
    try:
        norm_of(doc).validate()
    except ValueError as exc:
        raise ExportError(f"{path}: {exc}") from None
    for key in ("w", "best_w"):
        doc[key] = _matrix(path, key, doc[key], doc["n_actions"])
    doc["_path"] = path
    return doc


def norm_of(doc: dict[str, Any]) -> fp.ObsNorm:
    """The normalisation in the header's units [µrad, µrad/s], rounded to them."""
    n = doc["norm"]
    return fp.ObsNorm(int(round(n["theta_min_rad"] * 1e6)), int(round(n["theta_max_rad"] * 1e6)),
                      int(round(n["omega_max_rad_s"] * 1e6)))


def weights_of(doc: dict[str, Any], which: str = "best") -> np.ndarray:
    """The float W [6][n_actions] of a policy file read by load_policy: 'best' (validation-selected) or 'last'."""
    if which not in ("best", "last"):
        raise ExportError(f"which = {which!r}: expected 'best' or 'last'")
    return np.asarray(doc["best_w" if which == "best" else "w"], dtype=np.float64)


def export(policy: str | Path, out: str | Path, which: str = "best", frac_bits: int | None = None,
           float_reference: bool = True) -> weights_h.WeightsH:
    """Writes weights.h for a run's policy (atomically: the previous file stays whole if anything fails);
    returns what was written (parsed back)."""
    try:
        atomic.check_output_path(out, "--out")
    except ValueError as exc:
        raise ExportError(str(exc)) from None
    doc = load_policy(policy)
    w = weights_of(doc, which)
    tau_mnm = doc["tau_max_nm"] * 1000
    if abs(tau_mnm - round(tau_mnm)) > 1e-6 * max(1.0, tau_mnm):
        raise ExportError(f"{doc['_path']}: tau_max_nm is {doc['tau_max_nm']}, not a whole number of mN·m "
                          "(the header's unit)")
    try:
        return weights_h.write_weights_h(out, w, levels=None, frac_bits=frac_bits,
                                         decision_period_ms=doc["decision_period_ms"], norm=norm_of(doc),
                                         tau_max_mnm=int(round(tau_mnm)), banner_inputs=[doc["_path"]],
                                         float_reference=float_reference)
    except weights_h.WeightsHError as exc:
        raise ExportError(str(exc)) from exc
    except OSError as exc:
        raise ExportWriteError(f"{out}: cannot write ({exc.strerror}); the previous file, if any, is unchanged") from exc


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-export", description=__doc__.split("\n")[0])
    ap.add_argument("run", help="run directory (or its policy.json)")
    ap.add_argument("-o", "--out", required=True, help="weights.h to write (e.g. policy/weights.h)")
    ap.add_argument("--which", default="best", choices=("best", "last"),
                    help="best: the weights with the best greedy validation score (default); last: the final ones")
    ap.add_argument("--frac-bits", type=int, help="fraction bits of W (default: the most that fit)")
    ap.epilog = ("exit status (the same meanings in every pour program): 0 written; 1 the write failed (the previous "
                 "file is unchanged); 2 bad input: the command line or policy.json (the message names the field)")
    args = ap.parse_args(argv)
    try:
        res = export(args.run, args.out, args.which, args.frac_bits)
    except ExportError as exc:
        print(f"pour-export: error: {exc}", file=sys.stderr)
        return 1 if isinstance(exc, ExportWriteError) else 2
    print(f"pour-export: wrote {args.out} ({res.n_actions} actions, Q{15 - res.w_frac_bits}.{res.w_frac_bits}, "
          f"hash 0x{res.content_hash:08x})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
