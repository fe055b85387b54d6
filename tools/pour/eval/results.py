# SPDX-License-Identifier: MIT
"""pour-results: the results table (paper, baselines, vanilla REINFORCE, ours) on held-out seeds.

    pour-results --header policy/weights.h --group "vanilla REINFORCE" RUN... --group ours RUN... --out results/

The shipped policy and the baselines run through host_sim (the firmware core in-process for the
policy); the training runs' output float policies run greedy through libpoursim's C rollout on the
same seeds. Writes results/results.md and results/results.json.
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import atomic, cli
from pour.eval import evaluate
from pour.policy import export, weights_h
from pour.sim import envs
from pour.sim.episode import FINISH_MAX_S, POURED_MIN_PCT, SPILLED_MAX_PCT
from pour.train import executors, rundir

FIRST_SEED = 1_000_001  # held-out: training and validation seeds come from SeedSequence streams


def _row(name: str, how: str, poured: Sequence[float], spilled: Sequence[float], finish: Sequence[float],
         ret: Sequence[float], reversals: Sequence[float]) -> dict[str, Any]:
    poured, spilled, finish = np.asarray(poured), np.asarray(spilled), np.asarray(finish)
    ok = (poured >= POURED_MIN_PCT) & (spilled <= SPILLED_MAX_PCT) & (finish >= 0) & (finish <= FINISH_MAX_S)
    return {"name": name, "how": how, "episodes": int(poured.size), "poured_pct": float(poured.mean()),
            "poured_pct_min": float(poured.min()), "spilled_pct": float(spilled.mean()),
            "spilled_pct_max": float(spilled.max()),
            # An episode that never finishes (-1) counts as the full 10 s; -1 stays when none finished.
            "finish_s": float(np.mean(np.where(finish < 0, 10.0, finish))),
            "finish_s_max": float(np.max(np.where(finish < 0, 10.0, finish))) if np.any(finish >= 0) else -1.0,
            "unfinished": int(np.sum(finish < 0)),
            "return": float(np.mean(ret)), "reversals": float(np.mean(reversals)),
            "reversals_max": float(np.max(reversals)), "episodes_meeting_all_targets": int(ok.sum())}


def host_sim_row(name: str, args: Sequence[str], n: int, build_dir: str | None) -> dict[str, Any]:
    out = evaluate.run_host_sim([*args, "--episodes", str(n), "--seed", str(FIRST_SEED), "--quiet"], build_dir)
    per = out["per_episode"]
    return _row(name, "host_sim " + " ".join(args), [e["poured_pct"] for e in per], [e["spilled_pct"] for e in per],
                [e["finish_s"] for e in per], [e["return"] for e in per], [e["reversals"] for e in per])


def _greedy_metrics(kind: str, n_actions: int, period_ms: int, policy: Any, seed: int) -> dict[str, float]:
    """One held-out episode of 10 s on the nominal rig: a W through the C rollout, an MLP actor (a tuple of its
    layers) through the Gymnasium env, which runs the same simulator and firmware pipeline tick by tick."""
    if isinstance(policy, tuple):
        from pour.sim import gym_env  # _run_policies made sure the gym extra is there
        env = executors.cached(gym_env.PourEnv, kind, n_actions, period_ms, 10.0)
        return gym_env.greedy_metrics(env, gym_env.mlp_actor(policy), seed)
    return dict(executors.cached(envs.make_env, kind, n_actions, period_ms, 10.0).rollout(policy, seed, True).metrics)


def _mlp_layers(state: dict[str, Any], prefix: str) -> list[np.ndarray]:
    return [state[f"{prefix}{k}"] for k in range(sum(1 for key in state if key.startswith(prefix)))]


def _run_policies(run: Path) -> tuple[tuple[str, int, int], dict[str, Any], list[Any]]:
    """A run's (env kind, n_actions, decision period), its output policies ('best', 'last') and its validated
    history: W arrays for the trainer's and the linear actors' runs (policy.json, history_w), tuples of layers for
    an MLP actor's (actor.json, pour.examples.sb3_ppo --actor mlp: history_mlp_<k>)."""
    ck = rundir.load_checkpoint(run / "checkpoint.npz")
    if (run / "actor.json").exists():
        try:
            doc = json.loads((run / "actor.json").read_text(encoding="utf-8"))
            spec = (doc["config"]["env"]["kind"], int(doc["n_actions"]), int(doc["decision_period_ms"]))
        except (json.JSONDecodeError, UnicodeDecodeError, KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{run}/actor.json: not an MLP actor's description ({exc})") from None
        cli.require("gymnasium", "gym")  # an MLP actor runs through the Gymnasium env
        hist = _mlp_layers(ck, "history_mlp_")
        if not hist:
            raise ValueError(f"{run}: its checkpoint has no MLP actor history (history_mlp_0...)")
        history = [tuple(layer[i] for layer in hist) for i in range(len(hist[0]))]
        return spec, {"best": tuple(_mlp_layers(ck, "best_mlp_")), "last": history[-1]}, history
    doc = export.load_policy(run)
    spec = (doc["config"]["env"]["kind"], int(doc["n_actions"]), int(doc["decision_period_ms"]))
    if "history_w" not in ck:
        raise ValueError(f"{run}: its checkpoint has no W history (history_w): train it again with this pour-train")
    return spec, {w: export.weights_of(doc, w) for w in ("best", "last")}, list(ck["history_w"])


def _jobs(runs: Sequence[Path], n: int, which: str) -> list[tuple]:
    """The held-out episodes of several runs' policies ('best' or 'last', as export.weights_of's which), as
    _greedy_metrics jobs."""
    if which not in ("best", "last"):
        raise export.ExportError(f"which = {which!r}: expected 'best' or 'last'")
    jobs = []
    for run in runs:
        spec, out, _ = _run_policies(run)
        jobs += [(*spec, out[which], seed) for seed in range(FIRST_SEED, FIRST_SEED + n)]
    return jobs


def float_rows(name: str, runs: Sequence[Path], n: int, which: str = "best", workers: int | None = None
               ) -> dict[str, Any]:
    """The output policies of several runs (which 'best': policy.json's best_w, the best greedy-validated
    weights, or the last ones for configs with eval.select_best = false; 'last': the final weights),
    greedy, n held-out episodes each, pooled; on `workers` processes (default: one a core), same figures."""
    jobs = _jobs(runs, n, which)
    ms = _held_out(jobs, workers)
    p = [100 * m["v_target"] for m in ms]
    s = [100 * m["v_spill"] for m in ms]
    f = [m["finish_s"] for m in ms]
    r = [m["return"] for m in ms]
    what = "output" if which == "best" else "final"
    how = "Gymnasium env" if any(isinstance(j[3], tuple) for j in jobs) else "C rollout"
    return _row(name, f"{what} policies of {len(runs)} runs, greedy ({how})", p, s, f, r,
                [m["reversals"] for m in ms])


# Episodes to reach the bars: the first iteration whose training validation (greedy, seeds disjoint from
# training) is within PREFILTER of the bars is confirmed on the held-out seeds; the first confirmed one counts.
BAR_POURED_PCT, BAR_SPILLED_PCT = 98.0, 1.0
PREFILTER = (0.95, 0.02)   # validation V_target >= , V_spill <=
MAX_CHECKS = 12            # held-out confirmations per run at most (each costs n episodes of 10 s)


def _held_out(jobs: list[tuple], workers: int | None = None) -> list[dict[str, float]]:
    # Episodes are independent and seeded: run them on every core (or `workers`), results in job order.
    return executors.starmap(_greedy_metrics, jobs, workers or os.cpu_count() or 1)


def reach(run: Path, n: int) -> dict[str, Any]:
    """When a run's greedy policy first pours >= 98 % and spills <= 1 % on average over n held-out episodes
    of 10 s: its training episodes and wall time then (None when it never did), from the actor history in its
    checkpoint (W, or an MLP's layers, _run_policies) and the validation columns of its log."""
    spec, _, history = _run_policies(run)
    log = rundir.read_log(run / "log.csv")
    checks = 0
    for i, row in enumerate(log):
        vt, vs = float(row["eval_v_target"]), float(row["eval_v_spill"])
        if not (vt >= PREFILTER[0] and vs <= PREFILTER[1]) or i >= len(history):
            continue
        if checks == MAX_CHECKS:
            break
        checks += 1
        ms = _held_out([(*spec, history[i], seed) for seed in range(FIRST_SEED, FIRST_SEED + n)])
        poured = 100 * float(np.mean([m["v_target"] for m in ms]))
        spilled = 100 * float(np.mean([m["v_spill"] for m in ms]))
        if poured >= BAR_POURED_PCT and spilled <= BAR_SPILLED_PCT:
            return {"run": str(run), "episodes": int(row["episodes"]), "wall_s": float(row["wall_s"]),
                    "iteration": i, "poured_pct": poured, "spilled_pct": spilled, "checks": checks}
    return {"run": str(run), "episodes": None, "wall_s": None, "iteration": None, "checks": checks}


def _final_figures(runs: Sequence[Path], n: int) -> dict[str, float]:
    """Poured and spilled of the runs' last weights, greedy, n held-out episodes each, pooled."""
    ms = _held_out(_jobs(runs, n, "last"))
    spilled = [100 * m["v_spill"] for m in ms]
    return {"episodes": len(ms), "poured_pct": 100 * float(np.mean([m["v_target"] for m in ms])),
            "spilled_pct": float(np.mean(spilled)), "spilled_pct_max": float(np.max(spilled))}


def reach_row(name: str, runs: Sequence[Path], n: int) -> dict[str, Any]:
    """reach over a group's runs: how many reached, the median episodes and wall time, and the figures of the
    runs' final weights (the last iteration's, not the best validated) on the held-out seeds."""
    per = [reach(r, n) for r in runs]
    final = _final_figures(runs, n)
    got = [p for p in per if p["episodes"] is not None]
    budget = [int(_last_log_row(r)["episodes"]) for r in runs]
    # A run that never reached the bars counts as its whole budget and more: the median is then a lower bound.
    eps = sorted(p["episodes"] if p["episodes"] is not None else np.inf for p in per)
    wall = sorted(p["wall_s"] if p["wall_s"] is not None else np.inf for p in per)
    def finite(v: float) -> float | None:
        return float(v) if np.isfinite(v) else None
    return {"name": name, "runs": len(runs), "reached": len(got), "budget_episodes": max(budget),
            "episodes_median": finite(np.median(eps)), "episodes_min": finite(eps[0]),
            "episodes_max": finite(eps[-1]), "wall_s_median": finite(np.median(wall)), "per_run": per,
            "final": final}


def _last_log_row(run: Path) -> dict[str, str]:
    rows = rundir.read_log(run / "log.csv")
    if not rows:
        raise ValueError(f"{run}/log.csv has no rows")
    return rows[-1]


def reach_markdown(reach_rows: list[dict[str, Any]], rows: dict[str, dict[str, Any]], n: int) -> str:
    def num(v: float | None, fmt: str) -> str:
        return "not reached" if v is None else format(v, fmt)
    lines = ["", f"Learning from zero: training episodes and wall time until the greedy policy first pours >= "
             f"{BAR_POURED_PCT:g} % and spills <= {BAR_SPILLED_PCT:g} % on average over {n} held-out episodes "
             "(median over the runs; a run that never did counts as not reached), the output policies' "
             "(best validated weights) figures on the held-out seeds, and the final weights' (last iteration).", "",
             "| method | runs reaching 98 % / 1 % | episodes to reach (median; min–max) | wall s to reach (median) | "
             "budget (episodes) | poured % | spilled % (max) | reversals per 10 s (max) | finish s | "
             "final weights: poured % / spilled % (max) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in reach_rows:
        f = rows[r["name"]]
        spread = "" if r["episodes_min"] is None else \
            f"; {num(r['episodes_min'], '.0f')}–{num(r['episodes_max'], '.0f')}"
        lines.append(f"| {r['name']} | {r['reached']}/{r['runs']} | {num(r['episodes_median'], '.0f')}{spread} | "
                     f"{num(r['wall_s_median'], '.0f')} | {r['budget_episodes']} | {f['poured_pct']:.1f} | "
                     f"{f['spilled_pct']:.2f} ({f['spilled_pct_max']:.1f}) | {f['reversals']:.1f} "
                     f"({f['reversals_max']:.0f}) | {f['finish_s']:.2f} | {r['final']['poured_pct']:.1f} / "
                     f"{r['final']['spilled_pct']:.2f} ({r['final']['spilled_pct_max']:.1f}) |")
    return "\n".join(lines) + "\n"


def init_row(config_path: str, n: int) -> dict[str, Any]:
    """The policy a training config starts from, greedy, on the held-out seeds."""
    from pour.train import config
    cfg = config.load(config_path)
    w = rundir.weights(cfg, rundir.initial_params(cfg))
    sim = envs.make_env("sim", cfg.policy.n_actions, cfg.policy.decision_period_ms, 10.0)
    ms = [sim.rollout(w, seed, True).metrics for seed in range(FIRST_SEED, FIRST_SEED + n)]
    return _row(f"initial policy of {Path(config_path).name}", "greedy float, C rollout",
                [100 * m["v_target"] for m in ms], [100 * m["v_spill"] for m in ms],
                [m["finish_s"] for m in ms], [m["return"] for m in ms], [m["reversals"] for m in ms])


def markdown(rows: list[dict[str, Any]], n: int) -> str:
    lines = [f"Held-out seeds {FIRST_SEED}..{FIRST_SEED + n - 1} ({n} episodes of 10 s each per policy, "
             f"greedy). Targets: poured >= {POURED_MIN_PCT:g} %, spilled <= {SPILLED_MAX_PCT:g} %, finished within "
             f"{FINISH_MAX_S:g} s.", "",
             "| policy | poured % (mean / min) | spilled % (mean / max) | finish s (mean / max) | "
             "reversals per 10 s (mean / max) | return | episodes meeting all targets |",
             "|---|---|---|---|---|---|---|",
             "| paper (REINFORCE, pure-Python sim) | not reported | not reported | not reported | not reported | "
             "slight upward trend in 100 episodes (binary); no convergence in 500 (11 actions) | — |"]
    for r in rows:
        fin = "never (nothing poured)" if r["finish_s_max"] < 0 else f"{r['finish_s']:.2f} / {r['finish_s_max']:.2f}"
        lines.append(f"| {r['name']} | {r['poured_pct']:.1f} / {r['poured_pct_min']:.1f} | "
                     f"{r['spilled_pct']:.1f} / {r['spilled_pct_max']:.1f} | {fin} | "
                     f"{r['reversals']:.1f} / {r['reversals_max']:.0f} | {r['return']:.0f} | "
                     f"{r['episodes_meeting_all_targets']}/{r['episodes']} |")
    return "\n".join(lines) + "\n"


def _json_number(v: Any) -> Any:
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    raise TypeError(f"not JSON: {v!r}")


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-results", description=__doc__.split("\n")[0])
    ap.add_argument("--header", default="policy/weights.h")
    ap.add_argument("--group", action="append", nargs="+", metavar=("LABEL", "RUN_DIR"), default=[],
                    help="a label and its training runs (their final greedy float policies); repeatable")
    ap.add_argument("--group-last", action="append", nargs="+", metavar=("LABEL", "RUN_DIR"), default=[],
                    help="as --group, but the runs' final weights (not the best validated ones); repeatable")
    ap.add_argument("--init", metavar="CONFIG", help="also evaluate the initial policy of this training config")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--reach", action="store_true",
                    help="also the episodes and wall time each --group's runs took to reach 98 %% / 1 %% on the "
                         "held-out seeds, and their validation curves (reach_curves.png)")
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
        reach_rows = [reach_row(g[0], [Path(d) for d in g[1:]], n) for g in args.group] if args.reach else []
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
    text = markdown(rows, n)
    if reach_rows:
        text += reach_markdown(reach_rows, {r["name"]: r for r in rows}, n)
        plots.validation_curves({g[0]: [Path(d) for d in g[1:]] for g in args.group}, args.out / "reach_curves.png",
                                (BAR_POURED_PCT / 100, BAR_SPILLED_PCT / 100))
    atomic.write_atomic(args.out / "results.json",
                        json.dumps({"header_hash": f"0x{hdr.content_hash:08x}", "rows": rows, "reach": reach_rows},
                                   indent=1, default=_json_number) + "\n")
    atomic.write_atomic(args.out / "results.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
