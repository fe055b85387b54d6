# SPDX-License-Identifier: MIT
"""pour-results: the results table (paper, baselines, vanilla REINFORCE, ours) on held-out seeds.

    pour-results --header policy/weights.h --group "vanilla REINFORCE" RUN... --group ours RUN... --out results/

The shipped policy and the baselines run through host_sim (the firmware core in-process for the
policy); the training runs' output float policies run greedy through libpoursim's C rollout on the
same seeds. Writes results/results.md and results/results.json.
"""
from __future__ import annotations

import json
import multiprocessing as mp
import os
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import atomic, cli
from pour.eval import evaluate
from pour.policy import export, weights_h
from pour.sim import envs

FIRST_SEED = 1_000_001  # held-out: training and validation seeds come from SeedSequence streams


def _row(name: str, how: str, poured: Sequence[float], spilled: Sequence[float], finish: Sequence[float],
         ret: Sequence[float]) -> dict[str, Any]:
    poured, spilled, finish = np.asarray(poured), np.asarray(spilled), np.asarray(finish)
    ok = (poured >= 95) & (spilled <= 3) & (finish >= 0) & (finish <= 8)
    return {"name": name, "how": how, "episodes": int(poured.size), "poured_pct": float(poured.mean()),
            "poured_pct_min": float(poured.min()), "spilled_pct": float(spilled.mean()),
            "spilled_pct_max": float(spilled.max()),
            # An episode that never finishes (-1) counts as the full 10 s; -1 stays when none finished.
            "finish_s": float(np.mean(np.where(finish < 0, 10.0, finish))),
            "finish_s_max": float(np.max(np.where(finish < 0, 10.0, finish))) if np.any(finish >= 0) else -1.0,
            "unfinished": int(np.sum(finish < 0)),
            "return": float(np.mean(ret)), "episodes_meeting_all_targets": int(ok.sum())}


def host_sim_row(name: str, args: Sequence[str], n: int, build_dir: str | None) -> dict[str, Any]:
    out = evaluate.run_host_sim([*args, "--episodes", str(n), "--seed", str(FIRST_SEED), "--quiet"], build_dir)
    per = out["per_episode"]
    return _row(name, "host_sim " + " ".join(args), [e["poured_pct"] for e in per], [e["spilled_pct"] for e in per],
                [e["finish_s"] for e in per], [e["return"] for e in per])


_SIMS: dict[tuple[int, int], Any] = {}


def _greedy_metrics(job: tuple) -> dict[str, float]:
    n_actions, period_ms, w, seed = job
    if (n_actions, period_ms) not in _SIMS:
        _SIMS[(n_actions, period_ms)] = envs.make_env("sim", n_actions, period_ms, 10.0)
    return dict(_SIMS[(n_actions, period_ms)].rollout(w, seed, True).metrics)


def float_rows(name: str, runs: Sequence[Path], n: int, which: str = "best") -> dict[str, Any]:
    """The output policies of several runs (which 'best': policy.json's best_w, the best greedy-validated
    weights, or the last ones for configs with eval.select_best = false; 'last': the final weights),
    greedy, n held-out episodes each, pooled."""
    jobs = []
    for run in runs:
        doc = export.load_policy(run)
        w = export.weights_of(doc, which)
        jobs += [(int(doc["n_actions"]), int(doc["decision_period_ms"]), w, seed)
                 for seed in range(FIRST_SEED, FIRST_SEED + n)]
    # Episodes are independent and seeded: run them on every core, results in job order.
    with mp.get_context("fork").Pool(min(len(jobs), os.cpu_count() or 1)) as pool:
        ms = pool.map(_greedy_metrics, jobs, chunksize=1)
    p = [100 * m["v_target"] for m in ms]
    s = [100 * m["v_spill"] for m in ms]
    f = [m["finish_s"] for m in ms]
    r = [m["return"] for m in ms]
    what = "output" if which == "best" else "final"
    return _row(name, f"{what} float policies of {len(runs)} runs, greedy (C rollout)", p, s, f, r)


def init_row(config_path: str, n: int) -> dict[str, Any]:
    """The policy a training config starts from, greedy, on the held-out seeds."""
    from pour.train import config, reinforce
    cfg = config.load(config_path)
    p = np.zeros(reinforce.params_shape(cfg.policy.param, cfg.policy.n_actions))
    if cfg.policy.init == "beta":
        p = np.array(cfg.policy.init_beta, dtype=np.float64)
    w = reinforce.w_from_params(cfg.policy.param, p, cfg.policy.n_actions, cfg.policy.sharpness)
    sim = envs.make_env("sim", cfg.policy.n_actions, cfg.policy.decision_period_ms, 10.0)
    ms = [sim.rollout(w, seed, True).metrics for seed in range(FIRST_SEED, FIRST_SEED + n)]
    return _row(f"initial policy of {Path(config_path).name}", "greedy float, C rollout",
                [100 * m["v_target"] for m in ms], [100 * m["v_spill"] for m in ms],
                [m["finish_s"] for m in ms], [m["return"] for m in ms])


def markdown(rows: list[dict[str, Any]], n: int) -> str:
    lines = [f"Held-out seeds {FIRST_SEED}..{FIRST_SEED + n - 1} ({n} episodes of 10 s each per policy, "
             "greedy). Targets: poured >= 95 %, spilled <= 3 %, finished within 8 s.", "",
             "| policy | poured % (mean / min) | spilled % (mean / max) | finish s (mean / max) | return | "
             "episodes meeting all targets |",
             "|---|---|---|---|---|---|",
             "| paper (REINFORCE, pure-Python sim) | not reported | not reported | not reported | "
             "slight upward trend in 100 episodes (binary); no convergence in 500 (11 actions) | — |"]
    for r in rows:
        fin = "never (nothing poured)" if r["finish_s_max"] < 0 else f"{r['finish_s']:.2f} / {r['finish_s_max']:.2f}"
        lines.append(f"| {r['name']} | {r['poured_pct']:.1f} / {r['poured_pct_min']:.1f} | "
                     f"{r['spilled_pct']:.1f} / {r['spilled_pct_max']:.1f} | {fin} | {r['return']:.0f} | "
                     f"{r['episodes_meeting_all_targets']}/{r['episodes']} |")
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-results", description=__doc__.split("\n")[0])
    ap.add_argument("--header", default="policy/weights.h")
    ap.add_argument("--group", action="append", nargs="+", metavar=("LABEL", "RUN_DIR"), default=[],
                    help="a label and its training runs (their final greedy float policies); repeatable")
    ap.add_argument("--group-last", action="append", nargs="+", metavar=("LABEL", "RUN_DIR"), default=[],
                    help="as --group, but the runs' final weights (not the best validated ones); repeatable")
    ap.add_argument("--init", metavar="CONFIG", help="also evaluate the initial policy of this training config")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--build-dir", help="build directory holding bin/host_sim and lib/libpoursim.so")
    ap.add_argument("-o", "--out", default="results", type=Path)
    ap.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    args = ap.parse_args(argv)
    try:
        hdr = weights_h.parse_weights_h(args.header)
        n = args.episodes
        for flag, groups in (("--group", args.group), ("--group-last", args.group_last)):
            for g in groups:
                if len(g) < 2:
                    raise ValueError(f"{flag} {g[0]} has no run directory")
        # Each row, in the table's order, as work to do (the progress bar counts rows).
        todo = [lambda: host_sim_row("baseline: constant tilt rate", ["--baseline", "rate"], n, args.build_dir),
                lambda: host_sim_row("baseline: full torque", ["--baseline", "full"], n, args.build_dir),
                lambda: host_sim_row("baseline: hand-written pour (host_sim)", ["--baseline", "hand"], n,
                                     args.build_dir)]
        if args.init:
            todo.append(lambda: init_row(args.init, n))
        todo += [lambda g=g: float_rows(g[0], [Path(d) for d in g[1:]], n) for g in args.group]
        todo += [lambda g=g: float_rows(g[0], [Path(d) for d in g[1:]], n, "last") for g in args.group_last]
        todo.append(lambda: host_sim_row(f"ours, shipped {Path(args.header).name} (firmware core, fixed point)",
                                         ["--policy", args.header], n, args.build_dir))
        rows = [make() for make in cli.progress(todo, len(todo), "results", args.quiet, unit="row")]
    except (OSError, RuntimeError, ValueError, envs.EnvError, weights_h.WeightsHError, export.ExportError) as exc:
        print(f"pour-results: error: {exc}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    # The shipped policy's first held-out episode, 10 s, decisions of the float reference (Figs. 4, 6).
    from pour.eval import plots
    sim = envs.make_env("sim", hdr.n_actions, hdr.decision_period_ms, 10.0)
    ep = sim.rollout(hdr.w_float if hdr.w_float is not None else hdr.w_dequantized, FIRST_SEED, True)
    title = f"Shipped policy, held-out seed {FIRST_SEED}"
    plots.angle({"shipped policy": ep.x}, hdr.decision_period_ms, args.out / "shipped_angle.png", title)
    plots.volumes(ep.x, hdr.decision_period_ms, args.out / "shipped_volumes.png", title)
    atomic.write_atomic(args.out / "results.json",
                        json.dumps({"header_hash": f"0x{hdr.content_hash:08x}", "rows": rows}, indent=1) + "\n")
    atomic.write_atomic(args.out / "results.md", markdown(rows, n))
    print(markdown(rows, n))
    return 0


if __name__ == "__main__":
    sys.exit(main())
