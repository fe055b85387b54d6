# SPDX-License-Identifier: MIT
"""pour-eval: held-out evaluation of a policy, and float-vs-fixed-point agreement.

  pour-eval agree RUN_DIR --header policy/weights.h   # greedy float vs firmware fixed point on visited states
  pour-eval robust --header policy/weights.h          # nominal and each edge of the rig's uncertainty
"""
from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import cli, paths
from pour.policy import fixedpoint as fp
from pour.policy import weights_h
from pour.sim import envs


def state_of_features(x: np.ndarray, norm: fp.ObsNorm) -> list[int]:
    """The physical state (θ µrad, θ̇ µrad/s, volumes Q15) behind one float feature row.

    Exact inside the normalisation range, which is where the simulator's states are.
    """
    span = (norm.theta_max_urad - norm.theta_min_urad) * 1e-6
    theta = norm.theta_min_urad * 1e-6 + float(x[0]) * span
    wmax = norm.omega_max_urad_s * 1e-6
    omega = float(x[1]) * 2.0 * wmax - wmax
    return [int(round(theta * 1e6)), int(round(omega * 1e6))] + [fp.float_to_q15(float(v)) for v in x[2:5]]


def agreement(w_float: np.ndarray, header: weights_h.WeightsH, xs: np.ndarray) -> float:
    """Fraction of feature rows on which the float greedy action equals the fixed-point one."""
    pol = fp.FixedPolicy(header.w_q, header.w_frac_bits)
    float_act = np.argmax(np.asarray(xs) @ np.asarray(w_float), axis=1)
    same = 0
    for x, a in zip(xs, float_act):
        obs = fp.quantize_obs(header.norm, *state_of_features(x, header.norm))
        same += int(pol.eval(obs).action == int(a))
    return same / len(xs)


def held_out_seeds(n: int, base: int = 1_000_000) -> list[int]:
    """Seeds never used by training (training draws from SeedSequence streams)."""
    return [base + i for i in range(n)]


def host_sim_binary(build_dir: str | Path | None = None) -> Path:
    """The host_sim executable of a build directory (POUR_BUILD_DIR, or build/host)."""
    p = paths.binary("host_sim", build_dir)
    if p is not None:
        return p
    found = shutil.which("host_sim")
    if found:
        return Path(found)
    raise FileNotFoundError("host_sim not found: build it (cmake --build build/host) or pass --build-dir")


def run_host_sim(args: Sequence[str], build_dir: str | Path | None = None) -> Any:
    exe = host_sim_binary(build_dir)
    r = subprocess.run([str(exe), *args, "--json"], capture_output=True, text=True, timeout=3600)
    if r.returncode != 0:
        raise RuntimeError(f"{exe.name} {' '.join(args)} failed ({r.returncode}): {r.stderr.strip()[-500:]}")
    return json.loads(r.stdout)


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-eval", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    ag = sub.add_parser("agree", help="greedy float vs fixed-point agreement on held-out visited states")
    ag.add_argument("run", help="run directory (its policy.json gives the float W)")
    ag.add_argument("--header", required=True, help="the weights.h exported from that run")
    ag.add_argument("--episodes", type=int, default=20)
    ag.add_argument("--which", default="best", choices=("best", "last"))
    ag.add_argument("--episode-s", type=float, default=10.0, help="held-out episode length [s]")
    rb = sub.add_parser("robust", help="the robustness table: nominal and each edge of the rig's uncertainty")
    rb.add_argument("--header", default="policy/weights.h", help="the policy (firmware core in the loop)")
    rb.add_argument("-o", "--out", default="results/robustness", type=Path, help="folder for the table, JSON and plot")
    rb.add_argument("--nominal-episodes", type=int, default=100)
    rb.add_argument("--edge-episodes", type=int, default=30)
    rb.add_argument("--seed", type=int, default=held_out_seeds(2)[1], help="first held-out seed")
    rb.add_argument("--build-dir", help="build directory holding bin/host_sim and lib/libpoursim.so")
    rb.add_argument("--workers", type=int, default=2, help="host_sim processes at once")
    rb.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    rb.add_argument("--rig", type=Path, help="a rig file (pour-sysid): the nominal rig every scene starts from")
    args = ap.parse_args(argv)
    if args.cmd == "robust":
        return robust(args)
    from pour.policy import export
    try:
        doc = export.load_policy(args.run)
        w = export.weights_of(doc, args.which)
        hdr = weights_h.parse_weights_h(args.header)
        if not np.array_equal(hdr.w_q, weights_h.quantize_weights(w, hdr.w_frac_bits)):
            raise ValueError(f"{args.header} was not exported from {args.run} ({args.which} weights)")
        cfg = doc["config"]
        env = envs.make_env(cfg["env"]["kind"], int(doc["n_actions"]), int(doc["decision_period_ms"]),
                            args.episode_s, cfg["env"]["options"])
        xs = np.concatenate([env.rollout(w, s, True).x for s in held_out_seeds(args.episodes)])
        a = agreement(w, hdr, xs)
    except (export.ExportError, weights_h.WeightsHError, envs.EnvError, ValueError) as exc:
        print(f"pour-eval: error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps({"states": int(len(xs)), "agreement": a, "episodes": args.episodes}))
    return 0


def robust(args: argparse.Namespace) -> int:
    from pour.eval import robustness
    from pour.sim import poursim
    try:
        for name in ("nominal_episodes", "edge_episodes", "workers"):
            if not 1 <= getattr(args, name) <= 100000:
                raise ValueError(f"--{name.replace('_', '-')} wants an integer 1..100000")
        weights_h.parse_weights_h(args.header)
        if not args.out.parent.is_dir():
            raise ValueError(f"--out: folder {args.out.parent} does not exist")
        nominal, rig_sets, fill_edge = poursim.default_config(), [], robustness.FILL_EDGE
        if args.rig is not None:
            from pour.sysid import rig as srig
            rig = srig.load(args.rig)
            nominal.update(rig.values)
            rig_sets = srig.host_sim_sets(rig)
            # A weighed fill: its edges are the range pour-train --rig trains over.
            fill_edge = srig.centred({"rand_fill": fill_edge}, rig)["rand_fill"]
        rows = robustness.run(args.header, args.out, args.nominal_episodes, args.edge_episodes, args.seed,
                              lambda a: run_host_sim(a, args.build_dir), nominal, args.workers, args.quiet,
                              rig_sets, fill_edge)
    except (OSError, RuntimeError, ValueError, weights_h.WeightsHError, poursim.SimError) as exc:
        print(f"pour-eval: error: {exc}", file=sys.stderr)
        return 2
    print((args.out / "robustness.md").read_text(), end="")
    return 0 if all(r["bar_met"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
