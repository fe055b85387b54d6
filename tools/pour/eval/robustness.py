# SPDX-License-Identifier: MIT
"""The robustness evaluation: the shipped policy, firmware core in the loop, at nominal and at each edge of
the rig's uncertainty, on seeds never used in training.

  pour-eval robust --header policy/weights.h --out results/robustness

Each scene is one host_sim run (`--policy H --set KEY=VALUE ...`); scenes run in parallel, one process a
core (pour.train.executors.starmap's threads, each waiting on its host_sim). Writes robustness.json, robustness.md (the table) and robustness.png.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

from pour import atomic, cli
from pour.train import executors

# The bars (README, "Robustness").
NOMINAL_POURED_PCT, NOMINAL_SPILLED_PCT, NOMINAL_FINISH_S, NOMINAL_ALL_THREE = 98.0, 1.0, 6.0, 0.90
EDGE_POURED_PCT, EDGE_SPILLED_PCT = 95.0, 3.0
PEAK_OMEGA_RAD_S, REVERSALS_PER_EPISODE = 2.5, 30


@dataclass
class Scene:
    name: str
    sets: dict[str, Callable[[dict[str, float]], float]] = field(default_factory=dict)  # key -> f(nominal config)
    nominal: bool = False


FILL_EDGE = 0.2   # the fill's range, relative; a rig file that weighs the fill narrows it (rig.centred)


def scenes(fill: float = FILL_EDGE) -> list[Scene]:
    """Nominal, then each perturbation at the edge of the range the policy is trained over (the fill's: ±fill,
    relative)."""
    pct = f"{fill * 100:.2g}"
    return [
        Scene("nominal", nominal=True),
        Scene(f"fill -{pct} %", {"fill_depth": lambda c: (1.0 - fill) * c["fill_depth"]}),
        Scene(f"fill +{pct} %", {"fill_depth": lambda c: (1.0 + fill) * c["fill_depth"]}),
        Scene("target -2 cm", {"target_dx": lambda c: c["target_dx"] - 0.02}),
        Scene("target +2 cm", {"target_dx": lambda c: c["target_dx"] + 0.02}),
        Scene("pivot -2 cm", {"pivot_height": lambda c: c["pivot_height"] - 0.02}),
        Scene("pivot +2 cm", {"pivot_height": lambda c: c["pivot_height"] + 0.02}),
        Scene("motor torque -15 %", {"motor_peak_torque": lambda c: 0.85 * c["motor_peak_torque"]}),
        Scene("sensor lag x2", {"scale_delay_s": lambda c: 2.0 * c["scale_delay_s"],
                                "command_latency_ticks": lambda c: 2 * c["command_latency_ticks"]}),
    ]


def scene_args(scene: Scene, nominal: dict[str, float]) -> list[str]:
    out: list[str] = []
    for key, f in scene.sets.items():
        v = f(nominal)
        text = str(int(round(v))) if key == "command_latency_ticks" else format(v, ".6g")
        out += ["--set", f"{key}={text}"]
    return out


def judge(scene: Scene, s: dict[str, Any]) -> dict[str, Any]:
    """The row of one scene: means, worst cases and whether the bars hold."""
    per = s["per_episode"]
    n = len(per)
    finish = [e["finish_s"] for e in per]
    good = sum(1 for e in per if e["poured_pct"] >= NOMINAL_POURED_PCT and e["spilled_pct"] <= NOMINAL_SPILLED_PCT
               and 0 <= e["finish_s"] <= NOMINAL_FINISH_S)
    row = {
        "scene": scene.name, "episodes": n, "sets": s.get("sets", []),
        "poured_pct": s["poured_pct"], "spilled_pct": s["spilled_pct"],
        "spilled_pct_max": max(e["spilled_pct"] for e in per),
        "poured_l": s["poured_l"], "spilled_l": s["spilled_l"],
        "finish_s": s["finish_s"], "finish_max_s": max(finish) if all(f >= 0 for f in finish) else -1.0,
        "meet_all_three": good,
        "peak_omega_max_rad_s": max(e["peak_omega_rad_s"] for e in per),
        "peak_alpha_max_rad_s2": max(e["peak_alpha_rad_s2"] for e in per),
        "reversals_max": max(e["reversals"] for e in per),
        "reversals_mean": sum(e["reversals"] for e in per) / n,
    }
    motion = row["peak_omega_max_rad_s"] <= PEAK_OMEGA_RAD_S and row["reversals_max"] <= REVERSALS_PER_EPISODE
    if scene.nominal:
        ok = (row["poured_pct"] >= NOMINAL_POURED_PCT and row["spilled_pct"] <= NOMINAL_SPILLED_PCT
              and row["finish_max_s"] >= 0 and row["finish_max_s"] <= NOMINAL_FINISH_S
              and good >= math.ceil(NOMINAL_ALL_THREE * n))
    else:
        ok = row["poured_pct"] >= EDGE_POURED_PCT and row["spilled_pct"] <= EDGE_SPILLED_PCT
    row["bar_met"] = bool(ok and motion)
    return row


def table(rows: Sequence[dict[str, Any]], header: str, seed: int, counted: str = "episodes") -> str:
    """The markdown table; counted names what a row's count is (pour-robust-scale --repeats: "rigs", each the
    mean of its repeats)."""
    lines = [f"Robustness of `{header}` (firmware core in the loop, host_sim; seeds {seed}.. never used in "
             "training). Bars: nominal poured >= 98 %, spilled <= 1 %, every pour finished within 6 s, >= 90 % of "
             "episodes meet all three; each edge poured >= 95 %, spilled <= 3 %; everywhere peak |θ̇| <= 2.5 rad/s "
             "and <= 30 torque reversals per episode.", "",
             f"| scene | {counted} | poured % (L) | spilled % (L) | worst spill % | finish s (worst) | meet all three "
             "| peak θ̇ rad/s | peak θ̈ rad/s² | reversals mean (max) | bar |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['episodes']} | {r['poured_pct']:.1f} ({r['poured_l']:.2f}) "
            f"| {r['spilled_pct']:.2f} ({r['spilled_l']:.3f}) | {r['spilled_pct_max']:.1f} "
            f"| {r['finish_s']:.2f} ({r['finish_max_s']:.2f}) | {r['meet_all_three']}/{r['episodes']} "
            f"| {r['peak_omega_max_rad_s']:.2f} | {r['peak_alpha_max_rad_s2']:.0f} "
            f"| {r['reversals_mean']:.1f} ({r['reversals_max']:.4g}) | {'met' if r['bar_met'] else 'MISSED'} |")
    return "\n".join(lines) + "\n"


def plot(rows: Sequence[dict[str, Any]], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [r["scene"] for r in rows]
    y = list(range(len(rows)))[::-1]
    fig, ax = plt.subplots(1, 3, figsize=(13, 0.45 * len(rows) + 1.6), sharey=True)
    ax[0].barh(y, [r["poured_pct"] for r in rows], color="tab:blue")
    ax[0].axvline(EDGE_POURED_PCT, color="k", ls="--", lw=0.8)
    ax[0].set_xlim(80, 100)
    ax[0].set_xlabel("poured [%] (bar: 95 edges, 98 nominal)")
    ax[1].barh(y, [r["spilled_pct"] for r in rows], color="tab:red", label="mean")
    ax[1].plot([r["spilled_pct_max"] for r in rows], y, "k|", ms=12, label="worst episode")
    ax[1].axvline(EDGE_SPILLED_PCT, color="k", ls="--", lw=0.8)
    ax[1].set_xlabel("spilled [%] (bar: 3 edges, 1 nominal)")
    ax[1].legend(fontsize=8)
    ax[2].barh(y, [r["peak_omega_max_rad_s"] for r in rows], color="tab:green")
    ax[2].axvline(PEAK_OMEGA_RAD_S, color="k", ls="--", lw=0.8)
    ax[2].set_xlabel("peak |θ̇| [rad/s] (bar 2.5)")
    ax[0].set_yticks(y, names)
    fig.tight_layout()
    with atomic.atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def run(header: str, out: Path, nominal_episodes: int, edge_episodes: int, seed: int,
        run_host_sim: Callable[[Sequence[str]], Any], nominal_config: dict[str, float],
        workers: int = 2, quiet: bool = False, rig_sets: Sequence[str] = (),
        fill_edge: float = FILL_EDGE) -> list[dict[str, Any]]:
    """Every scene's row (and the table, JSON and plot in out); progress on stderr by episodes unless quiet.
    rig_sets: host_sim --set arguments of the nominal rig (a fitted rig file), before each scene's own;
    fill_edge: the fill's edges, relative."""
    out.mkdir(parents=True, exist_ok=True)
    todo = scenes(fill_edge)
    episodes = {sc.name: nominal_episodes if sc.nominal else edge_episodes for sc in todo}

    with cli.bar(sum(episodes.values()), f"{len(todo)} scenes", quiet, unit="episode") as progress:
        def one(scene: Scene) -> dict[str, Any]:
            sets = scene_args(scene, nominal_config)
            s = run_host_sim(["--policy", header, "--episodes", str(episodes[scene.name]), "--seed", str(seed),
                              "--quiet", *rig_sets, *sets])
            s["sets"] = sets[1::2]
            progress.update(episodes[scene.name])
            return judge(scene, s)

        rows = executors.starmap(one, [(sc,) for sc in todo], workers, threads=True)   # host_sim subprocesses
    doc = {"header": header, "seed": seed, "nominal_episodes": nominal_episodes, "edge_episodes": edge_episodes,
           "rig": list(rig_sets[1::2]), "rows": rows, "all_bars_met": all(r["bar_met"] for r in rows)}
    atomic.write_atomic(out / "robustness.json", json.dumps(doc, indent=1) + "\n")
    atomic.write_atomic(out / "robustness.md", table(rows, header, seed))
    plot(rows, out / "robustness.png")
    return rows
