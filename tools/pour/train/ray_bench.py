# SPDX-License-Identifier: MIT
"""Benchmark (not a test): the cost of running rollouts on Ray against the trainer's local process pool.

  python -m pour.train.ray_bench [--env toy|sim] [--episodes 64] [--episode-s 10]

Prints, for 1 and 2 CPUs: the scheduling overhead per task (no-op tasks: Ray tasks, pool.map items) and
per episode, the throughput in episodes/s and the efficiency against the ideal (CPUs / the CPU time of one
episode run in-process). Overhead per episode = (CPUs x wall - episodes x CPU time per episode) /
episodes: scheduling, transfer, and the CPU time other jobs on a shared machine took. The machine's
load average is printed before and after: the figures move with it.
"""
from __future__ import annotations

import os
import time

import numpy as np

from pour import cli
from pour.sim import envs
from pour.train import config as cfgmod
from pour.train import executors


def _noop(x: int) -> int:
    return x


def _cfg(kind: str, episode_s: float, workers: int) -> cfgmod.TrainConfig:
    return cfgmod.from_dict({"workers": workers, "policy": {"n_actions": 11, "decision_period_ms": 10},
                             "env": {"kind": kind, "episode_s": episode_s}})


def _policy() -> np.ndarray:
    w = np.zeros((6, 11))
    w[0, :] = np.linspace(3, -3, 11)
    w[5, :] = np.linspace(-2, 2, 11)
    return w


def episode_cost(kind: str, episode_s: float, n: int = 8) -> float:
    """CPU time of one episode run in-process [s] (this process's CPU time: what the episode costs
    whatever else the shared machine runs; the ideal throughput of c CPUs is c / this)."""
    env = envs.make_env(kind, 11, 10, episode_s)
    w = _policy()
    env.rollout(w, 0, False)
    t0 = time.process_time()
    for s in range(n):
        env.rollout(w, s + 1, False)
    return (time.process_time() - t0) / n


def ray_task_overhead(ray, n: int = 200) -> tuple[float, float]:
    """(per task when n are in flight, per task when each waits for the last) [s]."""
    noop = ray.remote(num_cpus=1)(_noop)
    ray.get([noop.remote(i) for i in range(20)])   # workers started
    t0 = time.perf_counter()
    ray.get([noop.remote(i) for i in range(n)])
    bulk = (time.perf_counter() - t0) / n
    t0 = time.perf_counter()
    for i in range(n // 4):
        ray.get(noop.remote(i))
    return bulk, (time.perf_counter() - t0) / (n // 4)


def pool_task_overhead(pool, n: int = 200) -> tuple[float, float]:
    pool.map(_noop, range(20), chunksize=1)
    t0 = time.perf_counter()
    pool.map(_noop, range(n), chunksize=1)
    bulk = (time.perf_counter() - t0) / n
    t0 = time.perf_counter()
    for i in range(n // 4):
        pool.apply(_noop, (i,))
    return bulk, (time.perf_counter() - t0) / (n // 4)


def throughput(runner, n_eps: int, reps: int = 3) -> float:
    """Best wall time [s] of one call that runs n_eps episodes."""
    w = _policy()
    seeds = list(range(1, n_eps + 1))
    runner.run(w, seeds[:4], False)   # warm: workers and their environments exist
    best = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        eps = runner.run(w, seeds, False)
        best = min(best, time.perf_counter() - t0)
        assert len(eps) == n_eps
    return best


def main() -> int:
    ap = cli.ArgumentParser(prog="python -m pour.train.ray_bench", description=__doc__.split("\n")[0])
    ap.add_argument("--env", choices=("toy", "sim"), default="toy")
    ap.add_argument("--episodes", type=int, default=64, help="episodes per measured call")
    ap.add_argument("--episode-s", type=float, default=10.0)
    args = ap.parse_args()
    ray = executors.import_ray()
    t_ep = episode_cost(args.env, args.episode_s)
    print(f"load average {os.getloadavg()[0]:.2f}; {args.env} episode of {args.episode_s:g} s in-process: "
          f"{t_ep * 1e3:.2f} ms CPU")
    print("| executor | CPUs | per task, bulk [ms] | per task, round trip [ms] | batch | episodes/s | "
          "efficiency | overhead per episode [ms] |", flush=True)
    print("|---|---|---|---|---|---|---|---|")
    for cpus in (1, 2):
        cfg = _cfg(args.env, args.episode_s, cpus)
        with executors.fork_pool(cpus) as pool:
            bulk, rt = pool_task_overhead(pool)
        runner = executors.Runner(cfg)
        if runner.pool is None:   # one worker runs in-process; measure a pool of one as the comparison
            runner.pool = executors.fork_pool(1, executors._init_worker, (runner.env_args,))
        wall = throughput(runner, args.episodes)
        runner.close()
        ideal = cpus / t_ep
        print(f"| local pool | {cpus} | {bulk * 1e3:.3f} | {rt * 1e3:.3f} | 1 (chunksize) | {args.episodes / wall:.1f} "
              f"| {args.episodes / wall / ideal:.2f} "
              f"| {(cpus * wall - args.episodes * t_ep) / args.episodes * 1e3:.2f} |", flush=True)
        executors.connect("local", num_cpus=cpus)
        try:
            bulk, rt = ray_task_overhead(ray)
            for per_task in (1, 8, None):
                r = executors.RayRunner(cfg, episodes_per_task=per_task)
                wall = throughput(r, args.episodes)
                r.close()
                label = per_task or f"{-(-args.episodes // cpus)} (1 per CPU)"
                print(f"| Ray | {cpus} | {bulk * 1e3:.3f} | {rt * 1e3:.3f} | {label} | {args.episodes / wall:.1f} "
                      f"| {args.episodes / wall / ideal:.2f} "
                      f"| {(cpus * wall - args.episodes * t_ep) / args.episodes * 1e3:.2f} |", flush=True)
        finally:
            ray.shutdown()
    print(f"load average {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
