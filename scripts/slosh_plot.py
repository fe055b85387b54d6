# SPDX-License-Identifier: MIT
"""Plots results/slosh/slosh_sweep.json (bench_slosh --json): the slosh's damping ratio against the retention's
RMS gaps to hydrostatics and to the weir, each point with the scatter of its two seed halves, the bars shaded.
Usage: .venv/bin/python scripts/slosh_plot.py [SWEEP_JSON [OUT_PNG]]. Written to OUT_PNG.tmp.png, then renamed."""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(argv):
    src = argv[1] if len(argv) > 1 else "results/slosh/slosh_sweep.json"
    dst = argv[2] if len(argv) > 2 else "results/slosh/slosh_tradeoff.png"
    try:
        with open(src, encoding="utf-8") as f:
            d = json.load(f)
        pts = [p for p in d["points"] if p["hydro_rms"] is not None and p["weir_rms"] is not None]
    except (OSError, ValueError, KeyError, TypeError) as e:
        print(f"slosh_plot: cannot read the sweep '{src}': {e}", file=sys.stderr)
        return 2
    if not pts:
        print(f"slosh_plot: '{src}' has no point with retention figures", file=sys.stderr)
        return 2
    bars = d["bars"]
    fig, axes = plt.subplots(1, 3, figsize=(16, 5.5))
    for ax, key, bar, name in [(axes[0], "hydro_rms", bars["hydro_rms"], "RMS gap to hydrostatics (0.02 rad/s)"),
                               (axes[1], "weir_rms", bars["weir_rms"], "RMS gap to the weir, C_d 0.6 (0.1 rad/s)")]:
        for p in pts:
            lo, hi = min(p["damping_halves"]), max(p["damping_halves"])
            ax.errorbar(100 * p[key], p["damping"], yerr=[[p["damping"] - min(lo, p["damping"])],
                                                          [max(hi, p["damping"]) - p["damping"]]],
                        fmt="o", color="C3" if p["label"] == "default" else "C0", capsize=3)
            ax.annotate(p["label"].replace("fluid_", ""), (100 * p[key], p["damping"]), fontsize=6,
                        xytext=(3, 3), textcoords="offset points")
        ax.axvspan(0, 100 * bar, color="C2", alpha=0.1)
        ax.axhspan(0, bars["damping"], color="C2", alpha=0.1)
        ax.set_xlabel(name + " [%]")
        ax.set_ylabel("slosh damping ratio (bars: the two seed halves)")
        ax.grid(alpha=0.3)
    ax = axes[2]
    for p in pts:
        ax.plot(p["x_real_time"], p["damping"], "o", color="C3" if p["label"] == "default" else "C0")
        ax.annotate(p["label"].replace("fluid_", ""), (p["x_real_time"], p["damping"]), fontsize=6,
                    xytext=(3, 3), textcoords="offset points")
    ax.axhspan(0, bars["damping"], color="C2", alpha=0.1)
    ax.set_xlabel("speed [x real time, one core, CPU time]")
    ax.set_ylabel("slosh damping ratio")
    ax.grid(alpha=0.3)
    fig.suptitle("150-particle liquid: slosh damping against the retention's errors (green: issue 38's bars)")
    fig.tight_layout()
    tmp = dst + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, dst)
    print(f"wrote {dst}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
