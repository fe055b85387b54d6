# SPDX-License-Identifier: MIT
"""The full drive's figures for docs/motor.md, from bench_motor's traces (scripts/bench.sh motor writes them):

  python -m pour.eval.motor_plots --step build/host/bench/current_step.csv \\
      --bus build/host/bench/pour_bus.csv --out docs/img

  motor_current_step.png -- the q current after a 10 A step on the locked rotor, against the designed loop
  motor_bus_pour.png     -- the bus voltage through the shipped policy's pour and return, against the rating
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

from pour.eval.plots import _save, plt

BOARD_RATING_V = 25.2  # the B-G431B-ESC1's 6S rating (docs/motor.md)
OVERVOLTAGE_TRIP_V = 28.0  # pour_drive_default_config().vbus_ov_mv


def read_trace(path: Path, columns: tuple[str, str]) -> tuple[np.ndarray, np.ndarray]:
    """The two named columns of a bench_motor CSV; ValueError naming the file if they are missing or empty."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or any(c not in rows[0] for c in columns):
        raise ValueError(f"{path}: expected columns {', '.join(columns)} and at least one row")
    try:
        x = np.array([float(r[columns[0]]) for r in rows])
        y = np.array([float(r[columns[1]]) for r in rows])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: a value is not a number ({exc})") from None
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        raise ValueError(f"{path}: a value is not finite")
    return x, y


def _plot(x: np.ndarray, y: np.ndarray, label: str, lines: Sequence[tuple[float, str, str, str]], xlabel: str,
          ylabel: str, title: str, legend: str, out: Path) -> None:
    """One trace with horizontal reference lines (value, colour, style, label or "")."""
    fig, ax = plt.subplots(figsize=(7, 4), dpi=120)
    ax.plot(x, y, lw=1.0, label=label)
    for value, colour, style, text in lines:
        ax.axhline(value, color=colour, lw=0.8, ls=style, label=text or None)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(loc=legend)
    ax.grid(alpha=0.3)
    _save(fig, out)


def current_step(path: Path, out: Path, ref: float = 10.0) -> None:
    t, iq = read_trace(path, ("t_s", "iq_a"))
    _plot(t * 1e3, iq, "q current (motor model, FOC in fixed point)",
          [(ref, "k", "--", "reference"), (0.1 * ref, "0.6", ":", ""), (0.9 * ref, "0.6", ":", "")],
          "time after the step [ms]", "i_q [A]", "Current step, locked rotor (bandwidth 3000 rad/s, 20 kHz)",
          "lower right", out)


def bus_pour(path: Path, out: Path) -> None:
    t, v = read_trace(path, ("t_s", "vbus_v"))
    _plot(t, v, "bus voltage, flux braking on (highest of each 1 ms)",
          [(BOARD_RATING_V, "r", "--", f"board rating {BOARD_RATING_V} V"),
           (OVERVOLTAGE_TRIP_V, "k", ":", f"overvoltage trip {OVERVOLTAGE_TRIP_V} V")],
          "time [s] (pour 0-10 s, return to upright 10-13 s)", "V_bus [V]",
          "DC bus through the shipped policy's pour (24 V supply, 200 uF)", "lower left", out)


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m pour.eval.motor_plots", description=__doc__.splitlines()[0])
    ap.add_argument("--step", required=True, type=Path, help="bench_motor --step-csv output")
    ap.add_argument("--bus", required=True, type=Path, help="bench_motor --bus-csv output")
    ap.add_argument("--out", required=True, type=Path, help="folder for the PNGs")
    args = ap.parse_args(argv)
    try:
        args.out.mkdir(parents=True, exist_ok=True)
        current_step(args.step, args.out / "motor_current_step.png")
        bus_pour(args.bus, args.out / "motor_bus_pour.png")
    except (OSError, ValueError) as exc:
        print(f"motor_plots: error: {exc}", file=sys.stderr)
        return 2
    print(f"motor_plots: wrote {args.out / 'motor_current_step.png'} and {args.out / 'motor_bus_pour.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
