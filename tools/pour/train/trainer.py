# SPDX-License-Identifier: MIT
"""pour-train: trains the softmax-linear pour policy with the config's method, rollouts in C on every core.

The method is the config's algo.kind, looked up in pour.train.methods; the run directory it keeps is
rundir.py's (config.json, log.csv, checkpoint.npz, policy.json), which a killed run resumes from.
"""
from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path
from typing import Any, Sequence

from pour import cli
from pour.sim import envs
from pour.sysid import rig as srig
from pour.train import config as cfgmod
from pour.train import executors, methods, reinforce, rundir
from pour.train.executors import Runner  # the local pool, the default executor (also as trainer.Runner)


def train(cfg: cfgmod.TrainConfig, run_dir: str | Path, resume: bool = True, quiet: bool = False,
          stop_after: int | None = None, make_runner: Any = Runner) -> rundir.RunResult:
    """Trains (or resumes) a run in run_dir with the method of cfg.algo.kind. stop_after: return after that
    many iterations this call. make_runner: cfg -> the episode runner (Runner, the local pool, or
    executors.RayRunner): same results."""
    return methods.method(cfg.algo.kind)(cfg, Path(run_dir), resume, quiet, stop_after, make_runner)


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-train", description=__doc__.split("\n")[0])
    ap.add_argument("config", help="TOML config (configs/train/*.toml)")
    ap.add_argument("-o", "--out", required=True, help="run directory (created; resumed if it holds a checkpoint)")
    ap.add_argument("--seed", type=int, help="override the config's seed")
    ap.add_argument("--iterations", type=int, help="override the config's iterations")
    ap.add_argument("--workers", type=int, help="override the config's workers")
    ap.add_argument("--fresh", action="store_true", help="discard an existing checkpoint in --out")
    ap.add_argument("--rig", type=Path, help="a rig file (pour-sysid): its values become the nominal rig, the "
                                             "randomisation centred on it with widths from its uncertainties")
    ap.add_argument("--quiet", action="store_true", help="no progress lines (iteration, return, time left) on stderr")
    ap.add_argument("--executor", choices=("local", "ray"), default="local",
                    help="where episodes run: 'local' process pool (default) or Ray tasks (pip install './tools[ray]')")
    ap.add_argument("--ray-address", default="local", metavar="auto|HOST:PORT",
                    help="--executor ray: 'local' (a Ray instance of this process), 'auto' (this machine's cluster) "
                         "or a head's HOST:PORT")
    args = ap.parse_args(argv)
    try:
        cfg = cfgmod.load(args.config)
        over = {k: getattr(args, k) for k in ("seed", "iterations", "workers") if getattr(args, k) is not None}
        if over:
            cfg = cfgmod.with_overrides(cfg, **over)
        if args.rig is not None:
            options = srig.centred(cfg.env.options, srig.load(args.rig))
            cfg = cfgmod.validate(dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, options=options)))
        res = train(cfg, args.out, resume=not args.fresh, quiet=args.quiet,
                    make_runner=executors.runner_factory("ray", args.ray_address) if args.executor == "ray" else Runner)
    except (cfgmod.ConfigError, envs.EnvError, rundir.TrainError, reinforce.GradientError, executors.ExecutorError,
            srig.RigError) as exc:
        print(f"pour-train: error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps({"run_dir": str(res.run_dir), "iterations": res.iterations, "wall_s": round(res.wall_s, 1),
                      "best_score": res.best_score}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
