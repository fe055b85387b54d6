# SPDX-License-Identifier: MIT
"""The trainer on the toy plant: reproducible from its config, resumable after a kill, clear errors."""
import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pour.train import config as cfgmod
from pour.sim import envs
from pour.train import methods, pg, rundir, trainer

TOY = {"seed": 5, "iterations": 6, "workers": 1,
       "policy": {"n_actions": 5, "decision_period_ms": 10},
       "algo": {"batch_episodes": 4, "lr": 0.1},
       "eval": {"every": 2, "episodes": 2},
       "env": {"kind": "toy", "episode_s": 3.0}}


def _cfg(**top):
    d = {k: (dict(v) if isinstance(v, dict) else v) for k, v in TOY.items()}
    d.update(top)
    return cfgmod.from_dict(d)


def _rows(run_dir):
    with open(Path(run_dir) / "log.csv", newline="") as f:
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(f)]


def _toml(d, path):
    lines = []
    for k, v in d.items():
        if not isinstance(v, dict):
            lines.append(f"{k} = {v!r}".replace("'", '"'))
    for k, v in d.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            for kk, vv in v.items():
                lines.append(f"{kk} = {str(vv).lower() if isinstance(vv, bool) else repr(vv)}".replace("'", '"'))
    Path(path).write_text("\n".join(lines) + "\n")


def test_same_config_same_run_whatever_the_worker_count(tmp_path):
    a = trainer.train(_cfg(workers=1), tmp_path / "a", quiet=True)
    b = trainer.train(_cfg(workers=2), tmp_path / "b", quiet=True)
    np.testing.assert_array_equal(a.w, b.w)
    np.testing.assert_array_equal(a.best_w, b.best_w)
    assert _rows(tmp_path / "a") == _rows(tmp_path / "b")
    assert len(_rows(tmp_path / "a")) == 6
    # The exporter's input, hence weights.h, is byte-identical too.
    assert (tmp_path / "a" / "policy.json").read_bytes() == (tmp_path / "b" / "policy.json").read_bytes()
    c = trainer.train(_cfg(seed=6), tmp_path / "c", quiet=True)
    assert not np.array_equal(a.w, c.w)


def test_resume_after_a_partial_run_is_bit_identical(tmp_path):
    full = trainer.train(_cfg(), tmp_path / "full", quiet=True)
    part = trainer.train(_cfg(), tmp_path / "part", quiet=True, stop_after=3)
    assert part.iterations == 3
    resumed = trainer.train(_cfg(), tmp_path / "part", quiet=True)
    assert resumed.iterations == 6
    np.testing.assert_array_equal(full.w, resumed.w)
    assert _rows(tmp_path / "full") == _rows(tmp_path / "part")


def test_killed_run_resumes_with_no_finished_iteration_lost(tmp_path):
    d = dict(TOY, iterations=16, env={"kind": "toy", "episode_s": 10.0})
    cfg_file = tmp_path / "toy.toml"
    _toml(d, cfg_file)
    run = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "pour.train.trainer", str(cfg_file), "--out", str(run), "--quiet"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline:
            if (run / "checkpoint.npz").exists() and len(_rows(run)) >= 4:
                break
            time.sleep(0.01)
        assert proc.poll() is None, "the run finished before it could be killed"
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
    with np.load(run / "checkpoint.npz") as z:
        done = int(z["iteration"])
    assert 3 <= done < 16
    rows_before = _rows(run)
    assert len(rows_before) >= done  # the log may hold one row more than the checkpoint, never fewer
    cfg = cfgmod.load(cfg_file)
    resumed = trainer.train(cfg, run, quiet=True)
    assert resumed.iterations == 16
    ref = trainer.train(cfg, tmp_path / "ref", quiet=True)
    np.testing.assert_array_equal(ref.w, resumed.w)
    assert _rows(run) == _rows(tmp_path / "ref")
    assert not list(run.glob("*.tmp"))


def test_learning_rate_decays_linearly_to_lr_final():
    cfg = _cfg(iterations=5, algo={"lr": 0.1, "lr_final": 0.02})
    assert [round(pg.learning_rate(cfg, i), 12) for i in range(5)] == [0.1, 0.08, 0.06, 0.04, 0.02]
    assert pg.learning_rate(_cfg(), 3) == 0.1


def test_resume_with_another_config_is_refused(tmp_path):
    trainer.train(_cfg(), tmp_path / "r", quiet=True, stop_after=1)
    with pytest.raises(rundir.TrainError, match="different config"):
        trainer.train(_cfg(seed=99), tmp_path / "r", quiet=True)
    trainer.train(_cfg(workers=2), tmp_path / "r", quiet=True, stop_after=1)  # workers do not matter


def test_training_improves_the_toy_policy(tmp_path):
    cfg = _cfg(iterations=40, workers=2, eval={"every": 39, "episodes": 4}, env={"kind": "toy", "episode_s": 6.0},
               algo={"batch_episodes": 8, "lr": 0.15, "entropy_coef": 0.0})
    res = trainer.train(cfg, tmp_path / "t", quiet=True)
    env = envs.ToyEnv(5, 10, 6.0)
    seeds = rundir.episode_seeds(123, rundir.STREAM_TEST, 0, 8)
    before = np.mean([env.rollout(np.zeros((6, 5)), s, False).metrics["v_target"] for s in seeds])
    after = np.mean([env.rollout(res.w, s, False).metrics["v_target"] for s in seeds])
    assert before < 0.05  # the uniform policy hardly tilts the bucket
    assert after > 0.5


BAD = [
    ({"seed": -1}, "seed = -1"),
    ({"iterations": 0}, "iterations = 0"),
    ({"workers": 1.5}, "workers = 1.5: expected an integer"),
    ({"policy": {"n_actions": 1}}, "policy.n_actions = 1: expected 2..16"),
    ({"policy": {"n_actions": 17}}, "policy.n_actions = 17"),
    ({"policy": {"decision_period_ms": 0}}, "policy.decision_period_ms = 0"),
    ({"policy": {"decision_period_ms": 7}}, "not a whole number of decision periods"),
    ({"algo": {"gamma": 1.5}}, "algo.gamma = 1.5"),
    ({"algo": {"gamma": float("nan")}}, "algo.gamma = nan: expected a finite number"),
    ({"algo": {"lr": 0.0}}, "algo.lr = 0.0"),
    ({"algo": {"lr": 0.1, "lr_final": 0.2}}, "algo.lr_final = 0.2: expected <= algo.lr"),
    ({"algo": {"optimizer": "rmsprop"}}, "algo.optimizer = 'rmsprop': expected 'adam', 'sgd' or 'natural'"),
    ({"algo": {"kind": "ppo"}}, "algo.kind = 'ppo'"),
    ({"algo": {"kind": "vanilla", "baseline": "none", "reward_to_go": True}}, "algo.reward_to_go must be False"),
    ({"algo": {"baseline": "loo", "batch_episodes": 1}}, "needs algo.batch_episodes >= 2"),
    ({"algo": {"entropy_coef": -0.1}}, "algo.entropy_coef = -0.1"),
    ({"algo": {"max_kl": -0.01}}, "algo.max_kl = -0.01: expected 0 <= max_kl <= 10"),
    ({"algo": {"kind": "vanilla", "batch_episodes": 1, "baseline": "none", "reward_to_go": False,
               "normalize_advantages": False, "entropy_coef": 0.0, "optimizer": "sgd", "max_kl": 0.1}},
     "algo.max_kl must be 0.0"),
    ({"algo": {"optimizer": "natural"}}, "algo.optimizer = 'natural' needs algo.max_kl > 0"),
    ({"algo": {"max_kl": 0.1, "max_kl_final": 0.2}}, "algo.max_kl_final = 0.2: expected 0 < max_kl_final <= algo.max_kl"),
    ({"algo": {"reward_to_go": "yes"}}, "algo.reward_to_go = 'yes': expected true or false"),
    ({"algo": {"learning_rate": 0.1}}, "unknown key(s) learning_rate"),
    ({"env": {"kind": "mujoco"}}, "env.kind = 'mujoco'"),
    ({"policy": {"param": "deep"}}, "policy.param = 'deep'"),
    ({"policy": {"param": "feedback", "init": "beta", "init_beta": [1, 2]}}, "expected 6 finite numbers"),
    ({"policy": {"init": "beta", "init_beta": [0, 0, 0, 0, 0, 0]}}, "needs policy.param = 'feedback'"),
    ({"policy": {"param": "feedback", "init": "beta", "init_beta": "fast"}}, "expected an array"),
    ({"policy": {"sharpness": 0.0}}, "policy.sharpness = 0.0"),
    ({"eval": {"every": 0}}, "eval.every = 0"),
    ({"colour": "blue"}, "unknown top-level key(s) colour"),
    ({"algo": 3}, r"\[algo\]: expected a table"),
]


@pytest.mark.parametrize("change,message", BAD)
def test_bad_config_values_are_named(change, message):
    d = {k: (dict(v) if isinstance(v, dict) else v) for k, v in TOY.items()}
    for k, v in change.items():
        if isinstance(v, dict) and isinstance(d.get(k), dict):
            d[k].update(v)
        else:
            d[k] = v
    with pytest.raises(cfgmod.ConfigError, match=message.replace("(", r"\(").replace(")", r"\)")
                       if "\\" not in message else message):
        cfgmod.from_dict(d)


def test_cli_reports_bad_files_and_values_with_exit_code_2(tmp_path):
    env = dict(os.environ)
    cases = {"missing.toml": None, "broken.toml": "seed = = 3\n", "badvalue.toml": "iterations = -5\n"}
    for name, text in cases.items():
        p = tmp_path / name
        if text is not None:
            p.write_text(text)
        r = subprocess.run([sys.executable, "-m", "pour.train.trainer", str(p), "--out", str(tmp_path / "o")],
                           capture_output=True, text=True, env=env, timeout=60)
        assert r.returncode == 2, r.stderr
        assert r.stderr.startswith("pour-train: error: ") and name in r.stderr
        assert "Traceback" not in r.stderr
    assert "iterations = -5" in r.stderr


def test_an_unknown_kind_is_refused_naming_every_registered_method(tmp_path):
    """The config, pour-train and trainer.train (a config built by hand) name the registry's kinds."""
    want = "algo.kind = 'ppo': expected one of the training methods 'vanilla', 'pg', 'ars', 'cem'"
    assert list(methods.METHODS) == ["vanilla", "pg", "ars", "cem"]
    with pytest.raises(cfgmod.ConfigError) as exc:
        cfgmod.from_dict({**TOY, "algo": {"kind": "ppo"}})
    assert str(exc.value) == want
    p = tmp_path / "ppo.toml"
    _toml({**TOY, "algo": {"kind": "ppo"}}, p)
    r = subprocess.run([sys.executable, "-m", "pour.train.trainer", str(p), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, timeout=60)
    assert (r.returncode, r.stderr) == (2, f"pour-train: error: {p}: {want}\n")
    import dataclasses
    cfg = _cfg()
    unchecked = dataclasses.replace(cfg, algo=dataclasses.replace(cfg.algo, kind="ppo"))
    with pytest.raises(cfgmod.ConfigError, match=want):
        trainer.train(unchecked, tmp_path / "hand", quiet=True)
    assert not (tmp_path / "hand").exists()


def test_the_trainer_runs_the_method_the_registry_maps_the_kind_to(tmp_path, monkeypatch):
    """trainer.train looks algo.kind up in methods.METHODS: replacing an entry changes what runs."""
    calls = []

    def stub(cfg, run_dir, resume, quiet, stop_after, make_runner):
        calls.append((cfg.algo.kind, run_dir, resume, quiet, stop_after, make_runner))
        return "ran"

    monkeypatch.setitem(methods.METHODS, "pg", stub)
    assert trainer.train(_cfg(), str(tmp_path / "r"), quiet=True, stop_after=2) == "ran"
    assert calls == [("pg", tmp_path / "r", True, True, 2, trainer.Runner)]
    assert methods.METHODS["vanilla"] is pg.train and methods.METHODS["cem"] is methods.METHODS["ars"]


def test_unknown_toy_option_is_an_env_error():
    with pytest.raises(envs.EnvError, match="unknown option 'gravty'"):
        envs.make_env("toy", 5, 10, 1.0, {"gravty": 9.8})


def test_plots_of_toy_runs(tmp_path):
    from pour.eval import plots
    for s in (1, 2):
        trainer.train(_cfg(seed=s, iterations=3), tmp_path / f"r{s}", quiet=True)
    v = cfgmod.from_dict(dict(TOY, iterations=8, algo={"kind": "vanilla", "batch_episodes": 1, "optimizer": "sgd",
                                                          "baseline": "none", "normalize_advantages": False,
                                                          "reward_to_go": False, "entropy_coef": 0.0,
                                                          "lr": 1e-4},
                              eval={"every": 4, "episodes": 1}))
    trainer.train(v, tmp_path / "v", quiet=True)
    rc = plots.main(["--group", "ours", str(tmp_path / "r1"), str(tmp_path / "r2"), "--group", "vanilla",
                     str(tmp_path / "v"), "--out", str(tmp_path / "png")])
    assert rc == 0
    for name in ("reward_curve.png", "ours_best_angle.png", "ours_best_volumes.png", "vanilla_best_angle.png"):
        data = (tmp_path / "png" / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    assert plots.main(["--group", "lonely", "--out", str(tmp_path / "png")]) == 2


def test_rollback_undoes_a_step_that_drops_the_return_and_resumes_bit_identically(tmp_path):
    # A rate far too large for the toy: some steps make the next batch's return drop.
    algo = {"batch_episodes": 4, "lr": 2.0, "max_kl": 10.0, "rollback": 0.05, "rollback_shrink": 0.1}
    cfg = _cfg(iterations=12, algo=algo)
    trainer.train(cfg, tmp_path / "full", quiet=True)
    rows = _rows(tmp_path / "full")
    rolled = [i for i, r in enumerate(rows) if r["rolled_back"] == "1"]
    assert rolled, "the test needs at least one rolled-back step"
    best = -np.inf
    for i, r in enumerate(rows):
        ret = float(r["return_mean"])
        if i in rolled:
            assert ret < best and float(r["step_scale"]) == 0.0 and float(r["kl"]) == 0.0
        best = max(best, ret) if i not in rolled else best
    # Each undone step shrinks the trust region by rollback_shrink.
    first = rolled[0]
    sched = [pg.max_kl(cfg, i) for i in range(12)]
    assert float(rows[first + 1]["kl_bound"]) == pytest.approx(sched[first + 1] * 0.1, rel=1e-9)
    trainer.train(cfg, tmp_path / "part", quiet=True, stop_after=first + 1)
    trainer.train(cfg, tmp_path / "part", quiet=True)
    assert _rows(tmp_path / "full") == _rows(tmp_path / "part")
