# SPDX-License-Identifier: MIT
"""The executors training and evaluation share (tools/pour/train/executors.py): starmap in this process, on
forked processes and on threads gives the same results in job order, and the evaluations that run on it
(pour-results' held-out episodes, pour-eval robust's scenes) give the same figures on one worker and on many."""
import os

import numpy as np
import pytest

from pour.eval import evaluate, results, robustness
from pour.sim import envs, poursim
from pour.train import config as cfgmod
from pour.train import executors, trainer


def where(a, b):
    return os.getpid(), a * 10 + b


def fails_on_three(a):
    if a == 3:
        raise ValueError(f"job {a} failed")
    return a


def test_starmap_keeps_the_job_order_wherever_the_jobs_run():
    jobs = [(a, a % 3) for a in range(7)]
    want = [a * 10 + a % 3 for a in range(7)]
    serial = executors.starmap(where, jobs)
    assert [v for _, v in serial] == want and {p for p, _ in serial} == {os.getpid()}
    forked = executors.starmap(where, jobs, workers=3)
    assert [v for _, v in forked] == want and os.getpid() not in {p for p, _ in forked}
    threads = executors.starmap(where, jobs, workers=3, threads=True)
    assert [v for _, v in threads] == want and {p for p, _ in threads} == {os.getpid()}
    assert executors.starmap(where, [], workers=3) == []


@pytest.mark.parametrize("workers,threads", [(1, False), (3, False), (3, True)])
def test_starmap_raises_a_jobs_own_error(workers, threads):
    with pytest.raises(ValueError, match="job 3 failed"):
        executors.starmap(fails_on_three, [(a,) for a in range(6)], workers=workers, threads=threads)


def test_cached_builds_once_per_arguments():
    made = []

    def make(*args):
        made.append(args)
        return object()

    a, b = executors.cached(make, "toy", 5, 10), executors.cached(make, "toy", 5, 10)
    c = executors.cached(make, "toy", 5, 20)
    assert a is b and c is not a and made == [("toy", 5, 10), ("toy", 5, 20)]


def _sim_run(tmp_path):
    cfg = cfgmod.from_dict({"seed": 4, "iterations": 2, "workers": 1,
                            "policy": {"n_actions": 11, "decision_period_ms": 10},
                            "algo": {"batch_episodes": 2, "lr": 0.1}, "eval": {"every": 1, "episodes": 1},
                            "env": {"kind": "sim", "episode_s": 2.0}})
    trainer.train(cfg, tmp_path / "run", quiet=True)
    return tmp_path / "run"


def test_held_out_episodes_give_the_same_figures_on_the_pool_and_in_process(tmp_path):
    run = _sim_run(tmp_path)
    serial = results.float_rows("r", [run, run], 3, workers=1)
    pooled = results.float_rows("r", [run, run], 3, workers=2)
    assert serial == pooled and serial["episodes"] == 6
    # ... and the figures of the episodes run directly, without the executors' cache.
    jobs = results._jobs([run], 3, "best")
    env = envs.make_env("sim", 11, 10, 10.0)
    direct = [dict(env.rollout(w, seed, True).metrics) for *_, w, seed in jobs]
    assert executors.starmap(results._greedy_metrics, jobs, workers=2) == direct
    assert 100 * np.mean([m["v_target"] for m in direct]) == pytest.approx(serial["poured_pct"])


def test_the_robustness_table_is_the_same_on_one_thread_and_on_several(tmp_path, source_dir, build_dir):
    header = str(source_dir / "policy" / "weights.h")

    def table(workers, out):
        rows = robustness.run(header, out, 1, 1, 1_000_001, lambda a: evaluate.run_host_sim(a, build_dir),
                              poursim.default_config(), workers, True)
        return rows, {n: (out / n).read_bytes() for n in ("robustness.json", "robustness.md", "robustness.png")}

    one, several = table(1, tmp_path / "one"), table(3, tmp_path / "three")
    assert one == several
    assert [r["scene"] for r in one[0]] == [s.name for s in robustness.scenes()]
