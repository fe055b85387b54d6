# SPDX-License-Identifier: MIT
"""pour-plots: PNG figures of training runs (the paper's Figs. 3-6, and volumes over time).

  reward curve  -- per-iteration mean episode return, mean and spread over seeds, one band per method
  angle         -- tilt angle over time of the best training episode of a run (Figs. 4 and 6)
  volumes       -- V_rotating, V_target, V_spill over time of an episode
  --liquid      -- the simulated liquid against physics: retention curves against an ideal liquid at three
                   fills (and the rigid pile of the first wave), and the slosh after a 12 deg tilt
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path
from typing import Any, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pour import atomic, cli  # noqa: E402
from pour.sim import envs  # noqa: E402



def _save(fig, out: Path) -> None:
    """Saves and closes fig; the PNG is written beside out and renamed (an old one stays whole on failure)."""
    try:
        with atomic.atomic_path(out) as tmp:
            fig.savefig(tmp)
    finally:
        plt.close(fig)

def _log(run_dir: Path) -> dict[str, np.ndarray]:
    with open(run_dir / "log.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{run_dir}/log.csv has no rows")
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def reward_curve(groups: dict[str, Sequence[Path]], out: Path, column: str = "return_mean",
                 title: str = "Episode return during training") -> None:
    """One line per group: mean over its runs, shaded +-1 std over runs, dotted min/max over runs,
    x on the batches of a run whose preceding step was undone (rollback)."""
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=120)
    for label, dirs in groups.items():
        logs = [_log(Path(d)) for d in dirs]
        n = min(len(lg[column]) for lg in logs)
        y = np.stack([lg[column][:n] for lg in logs])
        x = logs[0]["episodes"][:n]
        per_it = int(x[0]) if n else 1
        win = max(1, 16 // max(per_it, 1))
        if win > 1 and n >= win:
            # One episode per iteration: a running mean over 16 episodes, so that both methods' curves
            # average the same number of episodes per point.
            k = np.ones(win) / win
            y = np.stack([np.convolve(row, k, mode="valid") for row in y])
            x = x[win - 1:]
            label = f"{label}, running mean of {win}"
        m, s = y.mean(0), y.std(0)
        (line,) = ax.plot(x, m, label=f"{label} (n={len(dirs)} seeds)")
        ax.fill_between(x, m - s, m + s, color=line.get_color(), alpha=0.2)
        ax.plot(x, y.min(0), ":", color=line.get_color(), lw=0.8)
        ax.plot(x, y.max(0), ":", color=line.get_color(), lw=0.8)
        # Batches whose preceding step the trust region's rollback undid (algo.rollback): each run's own
        # value, marked, so a dip that was undone reads differently from one the policy stayed in.
        undone = [(lg["episodes"][i], lg[column][i]) for lg in logs if "rolled_back" in lg
                  for i in range(min(n, len(lg["rolled_back"]))) if lg["rolled_back"][i] == 1 and win == 1]
        if undone:
            ux, uy = zip(*undone)
            ax.plot(ux, uy, "x", color=line.get_color(), ms=6, mew=1.5, ls="none",
                    label=f"{label}: step undone (rollback)")
    ax.set_xlabel("training episodes")
    ax.set_ylabel(column.replace("_", " "))
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    _save(fig, out)


def episode_traces(x: np.ndarray, period_ms: int) -> dict[str, np.ndarray]:
    """Time [s], angle [deg] and volumes from the features of an episode's decisions."""
    t = np.arange(x.shape[0]) * period_ms * 1e-3
    theta = envs.THETA_MIN_RAD + x[:, 0] * (envs.THETA_MAX_RAD - envs.THETA_MIN_RAD)
    return {"t": t, "theta_deg": np.degrees(theta), "v_rot": x[:, 2], "v_tgt": x[:, 3], "v_spill": x[:, 4]}


def angle(episodes: dict[str, np.ndarray], period_ms: int, out: Path, title: str) -> None:
    """Angle over time, one line per labelled episode (features array)."""
    fig, ax = plt.subplots(figsize=(7, 3.6), dpi=120)
    for label, x in episodes.items():
        tr = episode_traces(x, period_ms)
        ax.plot(tr["t"], tr["theta_deg"], label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tilt angle θ [deg]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, out)


def volumes(x: np.ndarray, period_ms: int, out: Path, title: str) -> None:
    """V_rotating, V_target and V_spill over time of one episode."""
    tr = episode_traces(x, period_ms)
    fig, ax = plt.subplots(figsize=(7, 3.6), dpi=120)
    ax.plot(tr["t"], tr["v_rot"], label="V rotating")
    ax.plot(tr["t"], tr["v_tgt"], label="V target")
    ax.plot(tr["t"], tr["v_spill"], label="V spill")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("fraction of the liquid")
    ax.set_ylim(-0.02, 1.02)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, out)


def best_episode(run_dir: Path) -> np.ndarray:
    """Features of the run's best training episode (by return)."""
    with np.load(Path(run_dir) / "checkpoint.npz") as z:
        return np.array(z["best_ep_x"])


def liquid(out_dir: Path, prefix: str = "", quiet: bool = False) -> list[Path]:
    """liquid_retention.png and liquid_slosh.png: the measurements host_sim --bench prints (progress on
    stderr by measurement unless quiet)."""
    from pour.sim import poursim

    with cli.bar(5, "liquid", quiet, unit="measurement") as progress:
        return _liquid(out_dir, prefix, poursim, progress)


def _liquid(out_dir: Path, prefix: str, poursim: Any, progress: Any) -> list[Path]:
    base = poursim.default_config()
    depth = base["bucket_height"] - base["bucket_wall"]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for share, colour in ((0.60, "tab:blue"), (0.70, "tab:green"), (0.85, "tab:red")):
        r = poursim.retention({"fill_depth": share * depth})
        progress.update(1)
        deg = np.degrees(r.theta)
        ax.plot(deg, 100 * r.ideal, "--", color=colour, lw=1)
        ax.plot(deg, 100 * r.kept, color=colour,
                label=f"fill {100 * share:.0f} %: onset {np.degrees(r.onset):.0f} deg "
                      f"(ideal {np.degrees(r.ideal_onset):.0f}), RMS gap {100 * r.rms_gap:.1f} %")
    pile = poursim.retention({"fill_depth": 0.70 * depth, "fluid": 0}, n_seeds=1)
    progress.update(1)
    ax.plot(np.degrees(pile.theta), 100 * pile.kept, ":", color="0.3",
            label=f"rigid pile (fluid = 0), fill 70 %: RMS gap {100 * pile.rms_gap:.0f} %")
    ax.set(xlabel="tilt [deg] (servo, 0.02 rad/s)", ylabel="liquid left in the bucket [%]", xlim=(0, 125),
           title="Retention: simulated liquid (solid) against an ideal liquid (dashed)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths = [out_dir / f"{prefix}liquid_retention.png"]
    fig.savefig(paths[0], dpi=110)
    plt.close(fig)

    s = poursim.slosh()
    progress.update(1)
    t = np.arange(len(s.trace)) * base["dt"]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(t, 1e3 * s.trace, lw=1, label="centre of mass across the bucket, mean of 16 seeds")
    env = 1e3 * s.amplitude * np.exp(-s.damping * 2 * np.pi * s.freq * t)
    ax.plot(t, env, "k--", lw=0.8, label=f"fit: {s.freq:.2f} Hz (theory {s.freq_theory:.2f} Hz), "
                                         f"damping ratio {s.damping:.2f}")
    ax.plot(t, -env, "k--", lw=0.8)
    ax.set(xlabel="time after the 12 deg tilt [s]", ylabel="[mm]", title="Sloshing after a tilt", xlim=(0, t[-1]))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    paths.append(out_dir / f"{prefix}liquid_slosh.png")
    fig.savefig(paths[1], dpi=110)
    plt.close(fig)
    return paths


def validation_curves(groups: dict[str, Sequence[Path]], out: Path,
                      bars: tuple[float, float] = (0.98, 0.01)) -> None:
    """The greedy validation pour (log.csv's eval_v_target, top) and spill (eval_v_spill, bottom) of each group
    against training episodes (left) and against wall time (right): mean over the group's runs, shaded min to
    max, the bars (poured, spilled fractions) dashed. The volumes, not eval_score: the methods' rewards differ
    (a reversal cost or none), the liquid does not."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), dpi=120, sharex="col", sharey="row")
    for label, dirs in groups.items():
        logs = [_log(Path(d)) for d in dirs]
        n = min(len(lg["eval_v_target"]) for lg in logs)
        keep = np.all(np.stack([np.isfinite(lg["eval_v_target"][:n]) for lg in logs]), axis=0)
        xs = (logs[0]["episodes"][:n][keep], np.mean([lg["wall_s"][:n][keep] for lg in logs], axis=0))
        for row, column in enumerate(("eval_v_target", "eval_v_spill")):
            y = 100 * np.stack([lg[column][:n][keep] for lg in logs])
            for ax, x in zip(axes[row], xs):
                line, = ax.plot(x, y.mean(axis=0), label=f"{label} ({len(dirs)} runs)")
                ax.fill_between(x, y.min(axis=0), y.max(axis=0), color=line.get_color(), alpha=0.2)
    for row, bar in enumerate(bars):
        for ax in axes[row]:
            ax.axhline(100 * bar, color="k", ls="--", lw=0.8)
            ax.grid(alpha=0.3)
    axes[1][0].set_xlabel("training episodes")
    axes[1][1].set_xlabel("wall time [s] (mean over runs)")
    axes[0][0].set_ylabel("validation poured [%]")
    axes[1][0].set_ylabel("validation spilled [%]")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("Learning curves, greedy validation: mean over training seeds, shaded min to max, bars dashed")
    fig.tight_layout()
    _save(fig, out)


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-plots", description="Plots of training runs.")
    ap.add_argument("--group", action="append", nargs="+", metavar=("LABEL", "RUN_DIR"),
                    help="a label and its run directories (repeat per method)")
    ap.add_argument("--liquid", action="store_true",
                    help="plot the liquid against physics instead (retention, sloshing; ~1 min)")
    ap.add_argument("-o", "--out", required=True, help="output folder for the PNGs")
    ap.add_argument("--prefix", default="", help="file name prefix")
    ap.add_argument("--period-ms", type=int, default=10)
    ap.add_argument("--quiet", action="store_true", help="no progress bar on stderr (--liquid)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.liquid:
        from pour.sim.poursim import SimError
        try:
            for p in liquid(out, args.prefix, args.quiet):
                print(f"pour-plots: wrote {p}")
        except SimError as exc:
            print(f"pour-plots: error: {exc}", file=sys.stderr)
            return 2
        return 0
    if not args.group:
        print("pour-plots: error: give --group LABEL RUN_DIR... or --liquid", file=sys.stderr)
        return 2
    groups = {}
    for g in args.group:
        if len(g) < 2:
            print(f"pour-plots: error: --group {g[0]} has no run directory", file=sys.stderr)
            return 2
        groups[g[0]] = [Path(d) for d in g[1:]]
    try:
        reward_curve(groups, out / f"{args.prefix}reward_curve.png")
        for label, dirs in groups.items():
            # The best training episode over the group's runs.
            best = max(dirs, key=lambda d: float(np.load(d / "checkpoint.npz")["best_ep_return"]))
            x = best_episode(best)
            slug = label.lower().replace(" ", "_")
            angle({label: x}, args.period_ms, out / f"{args.prefix}{slug}_best_angle.png",
                  f"Best training episode, {label}")
            volumes(x, args.period_ms, out / f"{args.prefix}{slug}_best_volumes.png",
                    f"Best training episode, {label}")
    except (OSError, ValueError, KeyError) as exc:
        print(f"pour-plots: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
