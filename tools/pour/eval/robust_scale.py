# SPDX-License-Identifier: MIT
"""pour-robust-scale: the robustness evaluation over N randomised rigs, as Ray tasks.

  pour-robust-scale --header policy/weights.h --rigs 10000 --ray-address auto --out results/robust_scale

Each rig is one host_sim episode (the firmware core in the loop) whose scene, motor, liquid and sensors
are drawn from its seed by the simulator's rand_* keys (uniform ± around the nominal; defaults: the
ranges the policy is trained over, issue 10). Seeds are first_seed .. first_seed + N - 1, cut into
batches of --per-task consecutive seeds, one host_sim process per Ray task, so the result does not
depend on the cluster. The episodes are reduced to the table and the plot of `pour-eval robust`
(tools/pour/eval/robustness.py): all rigs, then the rigs by thirds of their drawn fill. Writes
robust_scale.json (every episode), robust_scale.md and robust_scale.png.

One episode is a noisy reading of a rig: the liquid is 150 particles (one is 0.67 %), and 1 mL more or less
in the bucket moves one rig's spill anywhere over 0-4.7 % (docs/training.md, "Retraining for a rig's fill").
--repeats K runs every rig K times, repeat r with the nominal fill depth scaled by 1 + (r - (K-1)/2)·1e-4
(1 mL steps of a 10 L fill, centred on the nominal), and judges each rig by the mean of its K episodes:
its expected spill, poured, finish time and reversals. Its peaks of θ̇ and θ̈ stay the worst of the K, and
"worst episode" in the table is still one episode's. K = 1 (the default) runs the rig as drawn.

--fill-schedule L configures each rig's firmware as its rig file would when the rig holds more than L litres:
the envelope's fill schedule, its knee at the onset angle of the rig's own fill less 3° (the simulator's
fill_schedule_l; docs/safety.md, "Fill schedule"). Rigs at or below L run the envelope as shipped.

Every node needs host_sim at the path the driver resolves (--build-dir, $POUR_BUILD_DIR or build/host).
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import atomic, cli
from pour.eval import evaluate, robustness
from pour.sim import poursim, rigs
from pour.train import executors

# The ranges the policy is trained over: the training distribution's rig file (configs/sim/randomised.cfg).
DEFAULT_RAND = rigs.load("randomised")
FIRST_SEED = 3_000_000   # held out: training seeds come from SeedSequence streams
FILL_STEP = 1e-4         # --repeats: relative fill step between repeats (1 mL of 10 L)
MAX_REPEATS = 1000
MEAN_KEYS = ("poured_pct", "spilled_pct", "liquid_l", "reversals")   # --repeats: a rig's mean of its repeats
WORST_KEYS = ("peak_omega_rad_s", "peak_alpha_rad_s2")                # and the worst of them


def run_batch(exe: str, header: str, first: int, n: int, sets: Sequence[str]) -> list[dict[str, Any]]:
    """One Ray task: host_sim over seeds first .. first + n - 1; its per-episode records, checked."""
    import subprocess
    args = [exe, "--policy", header, "--episodes", str(n), "--seed", str(first), "--quiet", "--json"]
    for s in sets:
        args += ["--set", s]
    r = subprocess.run(args, capture_output=True, text=True, timeout=3600)
    if r.returncode != 0:
        raise RuntimeError(f"host_sim --seed {first} --episodes {n} failed ({r.returncode}): {r.stderr.strip()[-300:]}")
    per = json.loads(r.stdout)["per_episode"]
    if [e["seed"] for e in per] != list(range(first, first + n)):
        raise RuntimeError(f"host_sim --seed {first} --episodes {n} returned seeds {[e['seed'] for e in per][:5]}...")
    return per


def summary(per: list[dict[str, Any]], sets: Sequence[str]) -> dict[str, Any]:
    """The summary host_sim prints, recomputed over pooled episodes (what robustness.judge reads)."""
    fin = [e["finish_s"] for e in per if e["finish_s"] >= 0]
    return {"per_episode": per, "sets": list(sets),
            "poured_pct": float(np.mean([e["poured_pct"] for e in per])),
            "spilled_pct": float(np.mean([e["spilled_pct"] for e in per])),
            "poured_l": float(np.mean([e["poured_pct"] * e["liquid_l"] / 100 for e in per])),
            "spilled_l": float(np.mean([e["spilled_pct"] * e["liquid_l"] / 100 for e in per])),
            "finish_s": float(np.mean(fin)) if fin else -1.0}


def fill_factors(repeats: int) -> list[float]:
    """The relative fill of each repeat: 1 mL steps centred on the nominal (just 1.0 for one repeat)."""
    return [1.0 + (r - (repeats - 1) / 2) * FILL_STEP for r in range(repeats)]


def per_rig(per: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One record per seed from its repeats: the means of MEAN_KEYS and finish_s (-1 if any repeat did not
    finish), the worst of WORST_KEYS and of the spill (spilled_pct_worst), and how many repeats there were."""
    by_seed: dict[int, list[dict[str, Any]]] = {}
    for e in per:
        by_seed.setdefault(e["seed"], []).append(e)
    rigs = []
    for seed in sorted(by_seed):
        eps = by_seed[seed]
        rig = {"seed": seed, "repeats": len(eps), "spilled_pct_worst": max(e["spilled_pct"] for e in eps)}
        rig.update({k: float(np.mean([e[k] for e in eps])) for k in MEAN_KEYS})
        rig.update({k: max(e[k] for e in eps) for k in WORST_KEYS})
        fin = [e["finish_s"] for e in eps]
        rig["finish_s"] = float(np.mean(fin)) if min(fin) >= 0 else -1.0
        rigs.append(rig)
    return rigs


def reduce(per: list[dict[str, Any]], sets: Sequence[str]) -> list[dict[str, Any]]:
    """Table rows: every rig, then the rigs by thirds of their drawn liquid volume."""
    per = sorted(per, key=lambda e: e["seed"])
    rows = [robustness.judge(robustness.Scene(f"{len(per)} randomised rigs"), summary(per, sets))]
    by_fill = sorted(per, key=lambda e: (e["liquid_l"], e["seed"]))
    k = len(by_fill)
    for i, name in enumerate(("least", "middle", "most")):
        part = by_fill[i * k // 3:(i + 1) * k // 3]
        if part:
            lo, hi = part[0]["liquid_l"], part[-1]["liquid_l"]
            rows.append(robustness.judge(robustness.Scene(f"third with the {name} liquid ({lo:.2f}-{hi:.2f} L)"),
                                         summary(part, sets)))
    return rows


def run(header: str, out: Path, rigs: int, first_seed: int, per_task: int | None, rand: dict[str, float],
        build_dir: str | None, address: str | None, num_cpus: int | None,
        quiet: bool = False, repeats: int = 1, fill_schedule_l: float = 0.0) -> tuple[list[dict[str, Any]], dict]:
    exe = str(evaluate.host_sim_binary(build_dir).resolve())
    header = str(Path(header).resolve())
    sets = [f"{k}={v:g}" for k, v in rand.items()] + ([f"fill_schedule_l={fill_schedule_l:g}"] if fill_schedule_l else [])
    factors = fill_factors(repeats)
    fills = [[]] if repeats == 1 else [[f"fill_depth={poursim.default_config()['fill_depth'] * f!r}"]
                                       for f in factors]
    with executors.RayTasks(address, num_cpus) as ray:
        cpus = ray.cpus()
        k = per_task or max(1, min(200, math.ceil(rigs / (2 * cpus))))
        t0 = time.monotonic()
        jobs = [(r, s) for r in range(repeats) for s in range(first_seed, first_seed + rigs, k)]
        what = f"{rigs} rigs" if repeats == 1 else f"{rigs} rigs x {repeats} repeats"
        batches = ray.starmap(run_batch, [(exe, header, s, min(k, first_seed + rigs - s), sets + fills[r])
                                          for r, s in jobs], what, quiet)
        per = [dict(e, repeat=r) if repeats > 1 else e for (r, _), batch in zip(jobs, batches) for e in batch]
        wall = time.monotonic() - t0
    rigs_per = per if repeats == 1 else per_rig(per)
    rows = reduce(rigs_per, sets)
    out.mkdir(parents=True, exist_ok=True)
    meta = {"header": header, "rigs": rigs, "repeats": repeats, "first_seed": first_seed, "per_task": k,
            "tasks": len(jobs), "cluster_cpus": cpus, "wall_s": round(wall, 1), "rand": rand,
            "fill_schedule_l": fill_schedule_l}
    doc = {**meta, "rows": rows, "per_episode": per} if repeats == 1 else \
        {**meta, "fill_factors": factors, "rows": rows, "per_rig": rigs_per, "per_episode": per}
    atomic.write_atomic(out / "robust_scale.json", json.dumps(doc) + "\n")
    how = "" if repeats == 1 else (
        f" Each rig ran {repeats} times, its fill depth stepped by {FILL_STEP:g} of the nominal between repeats; "
        f"a rig's figures are the means of its repeats (peaks the worst), \"worst spill\" is the worst rig's "
        f"mean, and the worst single episode spilled {max(e['spilled_pct'] for e in per):.1f} %.")
    atomic.write_atomic(out / "robust_scale.md",
                        f"Randomised rigs: {', '.join(sets)}; {rigs} rigs in {len(jobs)} Ray tasks of {k} on "
                        f"{cpus} CPUs, {wall:.0f} s.{how}\n\n" + robustness.table(rows, Path(header).name, first_seed,
                                                                     "episodes" if repeats == 1 else "rigs"))
    robustness.plot(rows, out / "robust_scale.png")
    return rows, meta


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-robust-scale", description=__doc__.split("\n")[0])
    ap.add_argument("--header", default="policy/weights.h", help="the policy (firmware core in the loop)")
    ap.add_argument("--rigs", type=int, default=100, help="randomised rigs (episodes), e.g. 10000 on a cluster")
    ap.add_argument("--seed", type=int, default=FIRST_SEED, help=f"first seed (default {FIRST_SEED})")
    ap.add_argument("--per-task", type=int, help="rigs per Ray task (default: 2 tasks a CPU, at most 200)")
    ap.add_argument("--repeats", type=int, default=1, metavar="K",
                    help="run each rig K times, its fill stepped by 1 mL, and judge it by the mean (default 1)")
    ap.add_argument("--fill-schedule", type=float, default=0.0, metavar="L",
                    help="give rigs above L litres the envelope's fill schedule from their rig file (default 0: off)")
    ap.add_argument("--set", action="append", default=[], metavar="rand_KEY=VALUE",
                    help="override a randomisation range (0 turns it off); repeatable")
    ap.add_argument("-o", "--out", default="results/robust_scale", type=Path)
    ap.add_argument("--build-dir", help="build directory holding bin/host_sim")
    ap.add_argument("--ray-address", default="local", metavar="local|auto|HOST:PORT")
    ap.add_argument("--num-cpus", type=int, help="CPUs of a local Ray instance (default: all)")
    ap.add_argument("--json", action="store_true",
                    help="print the run's figures as one JSON object instead of the table (both are written to --out)")
    ap.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    args = ap.parse_args(argv)
    try:
        if not 1 <= args.rigs <= 10_000_000:
            raise ValueError(f"--rigs {args.rigs}: expected 1..10000000")
        if args.per_task is not None and not 1 <= args.per_task <= 100_000:
            raise ValueError(f"--per-task {args.per_task}: expected 1..100000")
        if not 1 <= args.repeats <= MAX_REPEATS:
            raise ValueError(f"--repeats {args.repeats}: expected 1..{MAX_REPEATS}")
        if not (0.0 <= args.fill_schedule <= 100.0):   # also refuses nan
            raise ValueError(f"--fill-schedule {args.fill_schedule}: expected 0..100 L (0: off)")
        if not 0 <= args.seed <= 2**32 - 1 - args.rigs:
            raise ValueError(f"--seed {args.seed}: the seeds must stay below 2^32")
        rand = dict(DEFAULT_RAND)
        for s in args.set:
            key, sep, val = s.partition("=")
            if not sep or key not in DEFAULT_RAND:
                raise ValueError(f"--set {s!r}: expected one of {', '.join(DEFAULT_RAND)} = VALUE")
            try:
                rand[key] = float(val)
            except ValueError:
                raise ValueError(f"--set {s!r}: {val!r} is not a number") from None
        if not Path(args.header).is_file():
            raise ValueError(f"--header {args.header}: no such file")
        rows, meta = run(args.header, args.out, args.rigs, args.seed, args.per_task, rand, args.build_dir,
                         args.ray_address, args.num_cpus, args.quiet, args.repeats, args.fill_schedule)
    except (OSError, RuntimeError, ValueError) as exc:   # ExecutorError is a RuntimeError
        print(f"pour-robust-scale: error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps({**{k: meta[k] for k in ("rigs", "repeats", "tasks", "per_task", "cluster_cpus", "wall_s")},
                          "rows": rows, "out": str(args.out)}))
    else:
        print((args.out / "robust_scale.md").read_text(), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
