# SPDX-License-Identifier: MIT
"""pour-sweep: training runs over a grid or a random search of hyperparameters and seeds, on Ray.

  pour-sweep configs/train/toy.toml --grid algo.lr=0.03,0.1,0.3 --seeds 1,2,3 --out results/sweep
  pour-sweep configs/train/pour11.toml --random 8 --range algo.lr=0.01:0.3:log --range algo.max_kl=0.005:0.05 \\
      --seeds 1,2 --ray-address auto --out runs/sweep

Each trial (one point of the search and one seed) is one pour-train run in OUT/runs/<trial>/, run by one
plain Ray task on one CPU, then its output policy (best validated weights) runs greedy on the held-out
seeds of pour-results. Trials are independent and each resumes from its own checkpoint, so a sweep
that was interrupted (or whose worker died: Ray re-runs the task) continues where it stopped, and the
same sweep gives the same table whatever runs it. Writes:
  sweep.csv           one row per trial (its parameters, training figures, held-out figures)
  sweep.md            the results table of pour-results, one row per point (its seeds pooled)
  sweep.json          both, and the command's arguments
  reward_curve.png, spill_curve.png   pour-plots' training curves, one band per point over its seeds
  angle.png           pour-plots' angle plot: each point's best training episode (first seed)

Plain Ray tasks, not Ray Tune: a trial is a deterministic pour-train run that checkpoints and resumes
itself, and a grid or a seeded random search is a list of configs, so Tune's trial bookkeeping,
checkpointing and search algorithms would duplicate what the trainer has, for its dependencies (ray[tune]:
pandas, pyarrow, tensorboardX) in the pinned environment. Tune is the tool for an early-stopping scheduler
(ASHA, PBT) across many trials; pour-sweep has none.
"""
from __future__ import annotations

import csv
import io
import itertools
import json
import math
import shlex
import sys
import tomllib
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import atomic, cli
from pour.eval import results
from pour.sim import envs
from pour.train import config as cfgmod, executors

HELD_OUT_EPISODES = 20
HELD_OUT_EPISODE_S = 10.0   # as pour-results: a whole pour, whatever length the training episodes have


class SweepError(ValueError):
    """A search that cannot run (bad --grid/--range, unknown key)."""


def _value(key: str, text: str) -> Any:
    """A TOML scalar (integer, float, true/false, "string" or a bare word as a string)."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if text and all(c.isalnum() or c in "_-." for c in text):
            return text
        raise SweepError(f"{key} = {text!r}: not a TOML value") from None


def _key(key: str) -> tuple[str, ...]:
    parts = tuple(key.split("."))
    if not 1 <= len(parts) <= 2 or not all(parts):
        raise SweepError(f"{key!r}: expected KEY or SECTION.KEY (e.g. algo.lr, seed)")
    return parts


def parse_grid(items: Sequence[str]) -> dict[str, list[Any]]:
    out: dict[str, list[Any]] = {}
    for item in items:
        key, sep, vals = item.partition("=")
        _key(key)
        if not sep or not vals:
            raise SweepError(f"--grid {item!r}: expected KEY=V1,V2,...")
        out[key] = [_value(key, v.strip()) for v in vals.split(",")]
    return out


def parse_range(items: Sequence[str]) -> dict[str, tuple[float, float, bool]]:
    out: dict[str, tuple[float, float, bool]] = {}
    for item in items:
        key, sep, spec = item.partition("=")
        _key(key)
        parts = spec.split(":")
        try:
            lo, hi = float(parts[0]), float(parts[1])
        except (ValueError, IndexError):
            raise SweepError(f"--range {item!r}: expected KEY=LOW:HIGH or KEY=LOW:HIGH:log") from None
        log = len(parts) == 3 and parts[2] == "log"
        finite = math.isfinite(lo) and math.isfinite(hi) and lo < hi
        if len(parts) > 3 or (len(parts) == 3 and not log) or not finite or (log and lo <= 0):
            raise SweepError(f"--range {item!r}: expected finite LOW < HIGH (LOW > 0 for :log)")
        out[key] = (lo, hi, log)
    return out


def points(grid: dict[str, list[Any]], ranges: dict[str, tuple[float, float, bool]], n_random: int,
           search_seed: int) -> list[dict[str, Any]]:
    """The search's points: the grid's product, or n_random draws over the ranges (seeded), each with
    every grid combination."""
    base = [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())] if grid else [{}]
    if not n_random:
        if ranges:
            raise SweepError("--range needs --random N (how many points to draw)")
        return base
    if not ranges:
        raise SweepError("--random needs at least one --range")
    rng = np.random.default_rng(search_seed)
    out = []
    for _ in range(n_random):
        draw = {}
        for key, (lo, hi, log) in ranges.items():
            u = float(rng.random())
            v = math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo))) if log else lo + u * (hi - lo)
            draw[key] = float(f"{v:.4g}")   # 4 digits: the table and the run directories stay readable
        out += [{**b, **draw} for b in base]
    return out


def trial_config(base: dict[str, Any], point: dict[str, Any], seed: int, iterations: int | None) -> dict[str, Any]:
    """The config document of one trial: the base file with the point's values and the seed; one CPU."""
    doc = json.loads(json.dumps(base))
    for key, v in {**point, "seed": seed, "workers": 1, **({"iterations": iterations} if iterations else {})}.items():
        parts = _key(key)
        if len(parts) == 1:
            doc[parts[0]] = v
        else:
            doc.setdefault(parts[0], {})[parts[1]] = v
    return doc


def point_label(point: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v}" for k, v in point.items()) or "base config"


# --- one trial (a Ray task, or in-process) --------------------------------------------------------

def run_trial(doc: dict[str, Any], run_dir: str, held_out: int) -> dict[str, Any]:
    """Trains (or resumes, or finds finished) one run, then its output policy greedy on held-out seeds."""
    from pour.train import rundir, trainer
    cfg = cfgmod.from_dict(doc)
    res = trainer.train(cfg, run_dir, quiet=True)
    log = rundir.read_log(Path(run_dir) / "log.csv")
    env = envs.make_env(cfg.env.kind, cfg.policy.n_actions, cfg.policy.decision_period_ms, HELD_OUT_EPISODE_S,
                        cfg.env.options)
    eps = [env.rollout(res.best_w, s, True) for s in range(results.FIRST_SEED, results.FIRST_SEED + held_out)]
    return {"iterations": res.iterations, "wall_s": res.wall_s, "best_score": res.best_score,
            "return_mean_last": float(log[-1]["return_mean"]) if log else float("nan"),
            "held_out": [{"poured_pct": 100 * e.metrics["v_target"], "spilled_pct": 100 * e.metrics["v_spill"],
                          "finish_s": e.metrics["finish_s"], "reversals": e.metrics.get("reversals", float("nan")),  # the toy env counts none
                          "return": e.metrics.get("return", float(np.sum(e.rewards)))} for e in eps]}


def run(config_path: str, out: Path, pts: list[dict[str, Any]], seeds: Sequence[int], iterations: int | None,
        held_out: int, executor: str, address: str | None, num_cpus: int | None,
        command: str | None = None, quiet: bool = False) -> dict[str, Any]:
    try:
        base = tomllib.loads(Path(config_path).read_text())
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise cfgmod.ConfigError(f"{config_path}: cannot read config ({exc})") from exc
    trials = []
    for i, p in enumerate(pts):
        for s in seeds:
            doc = trial_config(base, p, s, iterations)
            try:
                cfgmod.from_dict(doc)   # every trial's config is checked before anything runs
            except cfgmod.ConfigError as exc:
                raise cfgmod.ConfigError(f"point {point_label(p)}, seed {s}: {exc}") from exc
            trials.append({"trial": f"p{i:02d}-s{s}", "point": i, "seed": s, "params": p, "doc": doc})
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(t["doc"], str((out / "runs" / t["trial"]).resolve()), held_out) for t in trials]
    desc = f"{len(jobs)} trials"
    if executor == "local":
        outs = executors.starmap(run_trial, jobs, desc=desc, quiet=quiet, unit="trial")
    else:
        with executors.RayTasks(address, num_cpus) as ray:
            outs = ray.starmap(run_trial, jobs, desc, quiet)   # an error or Ctrl-C stops the other trials
    for t, o in zip(trials, outs):
        t.update(o)
    return report(out, config_path, trials, pts, held_out, command)


def report(out: Path, config_path: str, trials: list[dict[str, Any]], pts: list[dict[str, Any]],
           held_out: int, command: str | None = None) -> dict[str, Any]:
    from pour.eval import plots
    keys = list(dict.fromkeys(k for p in pts for k in p))
    buf = io.StringIO()
    wr = csv.writer(buf, lineterminator="\n")
    wr.writerow(["trial", "point", "seed", *keys, "iterations", "best_score", "return_mean_last",
                 "held_out_poured_pct", "held_out_spilled_pct", "held_out_finish_s", "wall_s"])
    for t in trials:
        h = t["held_out"]
        wr.writerow([t["trial"], t["point"], t["seed"], *[t["params"].get(k, "") for k in keys], t["iterations"],
                     f"{t['best_score']:.6g}", f"{t['return_mean_last']:.6g}",
                     f"{np.mean([e['poured_pct'] for e in h]):.3f}", f"{np.mean([e['spilled_pct'] for e in h]):.3f}",
                     f"{np.mean([e['finish_s'] for e in h]):.3f}", f"{t['wall_s']:.1f}"])
    rows, groups = [], {}
    for i, p in enumerate(pts):
        mine = [t for t in trials if t["point"] == i]
        eps = [e for t in mine for e in t["held_out"]]
        label = point_label(p)
        rows.append(results._row(label, f"output float policies of {len(mine)} runs (seeds "
                                 f"{', '.join(str(t['seed']) for t in mine)}), greedy",
                                 [e["poured_pct"] for e in eps], [e["spilled_pct"] for e in eps],
                                 [e["finish_s"] for e in eps], [e["return"] for e in eps],
                                 [e["reversals"] for e in eps]))
        groups[label] = [Path(out) / "runs" / t["trial"] for t in mine]
    order = sorted(range(len(rows)), key=lambda k: -rows[k]["return"])
    table = (f"Sweep of `{config_path}`: {len(pts)} point(s) x {len(trials) // max(1, len(pts))} seed(s), best "
             "held-out return first." + (f" Made by `{command}`." if command else "") + "\n\n"
             + results.markdown([rows[k] for k in order], held_out))
    atomic.write_atomic(out / "sweep.csv", buf.getvalue())
    atomic.write_atomic(out / "sweep.md", table)
    doc = {"config": config_path, "points": pts, "rows": [rows[k] for k in order],
           "trials": [{k: v for k, v in t.items() if k != "doc"} for t in trials]}
    atomic.write_atomic(out / "sweep.json", json.dumps(doc, indent=1) + "\n")
    plots.reward_curve(groups, out / "reward_curve.png", title="Episode return during training, per point")
    plots.reward_curve(groups, out / "spill_curve.png", column="v_spill_mean",
                       title="Spilled fraction during training, per point")
    period = int(trials[0]["doc"].get("policy", {}).get("decision_period_ms", 10))
    plots.angle({lbl: plots.best_episode(d[0]) for lbl, d in groups.items()}, period, out / "angle.png",
                "Best training episode of each point (first seed)")
    return doc


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-sweep", description=__doc__.split("\n")[0])
    ap.add_argument("config", help="the base TOML config (configs/train/*.toml)")
    ap.add_argument("-o", "--out", required=True, type=Path, help="sweep folder (runs/, table, plots); re-run to resume")
    ap.add_argument("--grid", action="append", default=[], metavar="KEY=V1,V2",
                    help="a grid axis, e.g. algo.lr=0.03,0.1 (repeatable: the product)")
    ap.add_argument("--random", type=int, default=0, metavar="N", help="N random points over the --range axes")
    ap.add_argument("--range", action="append", default=[], metavar="KEY=LOW:HIGH[:log]")
    ap.add_argument("--search-seed", type=int, default=0, help="seed of the random search's draws")
    ap.add_argument("--seeds", default="1,2", help="training seeds, each point runs with every one (default 1,2)")
    ap.add_argument("--iterations", type=int, help="override the config's iterations")
    ap.add_argument("--held-out", type=int, default=HELD_OUT_EPISODES,
                    help=f"held-out greedy episodes per run (default {HELD_OUT_EPISODES})")
    ap.add_argument("--executor", choices=("ray", "local"), default="ray",
                    help="'ray' (default): one task per trial; 'local': trials one after another in this process")
    ap.add_argument("--ray-address", default="local", metavar="local|auto|HOST:PORT")
    ap.add_argument("--num-cpus", type=int, help="CPUs of a local Ray instance (default: all)")
    ap.add_argument("--json", action="store_true",
                    help="print where the sweep went and its rows as one JSON object instead of the table")
    ap.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    args = ap.parse_args(argv)
    try:
        try:
            seeds = [int(s) for s in args.seeds.split(",")]
        except ValueError:
            raise SweepError(f"--seeds {args.seeds!r}: expected integers separated by commas") from None
        if not 1 <= args.held_out <= 1000:
            raise SweepError(f"--held-out {args.held_out}: expected 1..1000")
        if not 0 <= args.random <= 10000:
            raise SweepError(f"--random {args.random}: expected 0..10000")
        pts = points(parse_grid(args.grid), parse_range(args.range), args.random, args.search_seed)
        doc = run(args.config, args.out, pts, seeds, args.iterations, args.held_out, args.executor,
                  args.ray_address, args.num_cpus,
                  shlex.join(["pour-sweep", *(sys.argv[1:] if argv is None else argv)]), args.quiet)
    except (SweepError, cfgmod.ConfigError, envs.EnvError, executors.ExecutorError) as exc:
        print(f"pour-sweep: error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps({"out": str(args.out), "trials": len(doc["trials"]), "rows": doc["rows"]}))
    else:
        print((args.out / "sweep.md").read_text(), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
