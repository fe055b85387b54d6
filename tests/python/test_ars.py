# SPDX-License-Identifier: MIT
"""Random search (algo.kind = 'ars') on the toy plant: learns from zero, reproducible and resumable, refuses
bad options and foreign state by name, and stops a diverging run with its best weights kept."""
import json

import numpy as np
import pytest

from pour.policy import export
from pour.sim import envs
from pour.train import ars, reinforce, rundir, trainer
from pour.train import config as cfgmod

TOY = {"seed": 3, "iterations": 6, "workers": 1,
       "policy": {"n_actions": 11, "decision_period_ms": 10, "param": "full"},
       "algo": {"kind": "ars", "entropy_coef": 0.0},
       "ars": {"directions": 4, "top": 2, "step_size": 0.5, "noise": 1.0},
       "eval": {"every": 1, "episodes": 2},
       "env": {"kind": "toy", "episode_s": 3.0}}


def _cfg(**changes):
    d = json.loads(json.dumps(TOY))
    for k, v in changes.items():
        if isinstance(v, dict) and isinstance(d.get(k), dict):
            d[k].update(v)
        else:
            d[k] = v
    return cfgmod.from_dict(d)


def _v_target(w, n=8):
    env = envs.ToyEnv(11, 10, 3.0)
    seeds = rundir.episode_seeds(77, rundir.STREAM_TEST, 0, n)
    return float(np.mean([env.rollout(w, s, True).metrics["v_target"] for s in seeds]))


def test_ars_from_zero_learns_to_pour_the_toy(tmp_path):
    res = trainer.train(_cfg(iterations=20), tmp_path / "r", quiet=True)
    assert _v_target(np.zeros((6, 11))) == 0.0   # the zero policy pushes the bucket against its rest
    assert _v_target(res.best_w) > 0.15 and res.best_score > 0.05
    ck = rundir.load_checkpoint(tmp_path / "r" / "checkpoint.npz")
    assert ck["history_w"].shape == (20, 6, 11)
    np.testing.assert_array_equal(ck["history_w"][-1], res.w)


def test_same_run_whatever_the_workers_and_after_a_resume(tmp_path):
    a = trainer.train(_cfg(workers=1), tmp_path / "a", quiet=True)
    b = trainer.train(_cfg(workers=2), tmp_path / "b", quiet=True)
    trainer.train(_cfg(), tmp_path / "c", quiet=True, stop_after=2)
    c = trainer.train(_cfg(), tmp_path / "c", quiet=True)
    for r in (b, c):
        np.testing.assert_array_equal(a.w, r.w)
        np.testing.assert_array_equal(a.best_w, r.best_w)
    assert (tmp_path / "a" / "policy.json").read_bytes() == (tmp_path / "c" / "policy.json").read_bytes()
    d = trainer.train(_cfg(seed=4), tmp_path / "d", quiet=True)
    assert not np.array_equal(a.w, d.w)


def test_step_keeps_the_top_directions_and_scales_by_their_spread():
    deltas = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    r_plus, r_minus = np.array([3.0, 0.0, 1.0]), np.array([1.0, 2.0, 0.5])
    step, sigma = ars.ars_step(deltas, r_plus, r_minus, top=2, alpha=0.5)
    # max(R+, R-): 3, 2, 1 -> directions 0 and 1; sigma of [3, 0, 1, 2].
    assert sigma == pytest.approx(np.std([3.0, 0.0, 1.0, 2.0]))
    np.testing.assert_allclose(step, 0.5 / (2 * sigma) * np.array([2.0, -2.0]))
    step, sigma = ars.ars_step(deltas, np.ones(3), np.ones(3), top=3, alpha=0.5)
    assert sigma == 0.0 and not step.any()   # no information, no step


def test_state_stats_merge_batches_to_the_pooled_mean_and_std():
    rng = np.random.default_rng(5)
    xs = [rng.normal(size=(n, 6)) * [0.3, 0.05, 0.4, 0.4, 0.001, 0.0] + [0.5, 0.5, 0.5, 0.4, 0.0, 1.0]
          for n in (7, 1, 30)]
    st = ars.StateStats()
    np.testing.assert_array_equal(st.std(0.01), np.ones(5))   # nothing seen: the raw coordinates
    for x in xs:
        st.add(x)
    pooled = np.concatenate(xs)[:, :5]
    np.testing.assert_allclose(st.mean, pooled.mean(axis=0), rtol=1e-12)
    np.testing.assert_allclose(st.std(0.0), pooled.std(axis=0), rtol=1e-10)
    assert st.std(0.01)[4] == 0.01 and st.n == 38   # V_spill barely moves: floored


@pytest.mark.parametrize("param", ["full", "feedback"])
def test_state_coords_run_the_standardised_policy_on_raw_features(param):
    rng = np.random.default_rng(6)
    mean, std = rng.uniform(0.2, 0.8, 5), rng.uniform(0.01, 0.5, 5)
    p = rng.normal(size=(6, 11) if param == "full" else (6,))
    x = np.column_stack([rng.uniform(0, 1, (20, 5)), np.ones(20)])
    xs = np.column_stack([(x[:, :5] - mean) / std, np.ones(20)])
    w_raw = reinforce.w_from_params(param, ars.state_coords(p, mean, std), 11, 50.0)
    w_std = reinforce.w_from_params(param, p, 11, 50.0)
    np.testing.assert_allclose(x @ w_raw, xs @ w_std, rtol=1e-9, atol=1e-9)


def test_v2_normalised_search_learns_the_toy_and_resumes_bit_identically(tmp_path):
    v2 = _cfg(iterations=20, ars={"normalize_states": True, "state_std_min": 0.02})
    res = trainer.train(v2, tmp_path / "a", quiet=True)
    assert _v_target(res.best_w) > 0.15
    ck = rundir.load_checkpoint(tmp_path / "a" / "checkpoint.npz")
    assert ck["state_n"] > 0 and np.all(ck["state_m2"] >= 0)
    trainer.train(v2, tmp_path / "b", quiet=True, stop_after=7)
    b = trainer.train(v2, tmp_path / "b", quiet=True)
    np.testing.assert_array_equal(res.w, b.w)
    np.testing.assert_array_equal(res.best_w, b.best_w)
    v1 = trainer.train(_cfg(iterations=20), tmp_path / "c", quiet=True)
    assert not np.array_equal(v1.w, res.w)


def test_features_limit_the_search_to_their_gains(tmp_path):
    res = trainer.train(_cfg(ars={"features": ["theta", "bias"]}), tmp_path / "r", quiet=True)
    ck = rundir.load_checkpoint(tmp_path / "r" / "checkpoint.npz")
    assert not ck["history_w"][:, [1, 2, 3, 4]].any()        # omega and the volumes keep their 0 gains
    assert ck["history_w"][:, 0].any() and ck["history_w"][:, 5].any() and res.w[[0, 5]].any()


def test_random_init_is_seeded_and_scaled():
    a = rundir.initial_params(_cfg(policy={"init": "random", "init_scale": 0.1}))
    b = rundir.initial_params(_cfg(policy={"init": "random", "init_scale": 0.1}))
    c = rundir.initial_params(_cfg(seed=9, policy={"init": "random", "init_scale": 0.1}))
    np.testing.assert_array_equal(a, b)
    assert a.shape == (6, 11) and not np.array_equal(a, c) and 0 < np.abs(a).max() < 0.5


def test_configs_that_do_not_use_the_new_options_keep_their_digest():
    d = _cfg(algo={"kind": "pg", "entropy_coef": 0.01}).to_dict()
    assert "ars" not in d and "init_scale" not in d["policy"]
    assert "ars" in _cfg().to_dict()
    assert not {"normalize_states", "state_std_min", "features"} & set(_cfg().to_dict()["ars"])
    v2 = _cfg(ars={"normalize_states": True, "features": ["bias"]}).to_dict()["ars"]
    assert v2["normalize_states"] and v2["state_std_min"] == 0.01 and v2["features"] == ["bias"]


BAD = [
    ({"ars": {"top": 5}}, "ars.top = 5: expected 1..ars.directions (4)"),
    ({"ars": {"directions": 0}}, "ars.directions = 0: expected 1..256"),
    ({"ars": {"noise": 0.0}}, "ars.noise = 0.0: expected 0 < nu <= 10"),
    ({"ars": {"noise": 0.5, "noise_final": 0.6}}, "ars.noise_final = 0.6: expected 0 < nu_final <= ars.noise"),
    ({"ars": {"step_size": float("nan")}}, "ars.step_size = nan: expected a finite number"),
    ({"ars": {"step_size": 0.1, "step_size_final": 0.2}}, "ars.step_size_final = 0.2: expected <= ars.step_size"),
    ({"ars": {"episodes_per_direction": 0}}, "ars.episodes_per_direction = 0: expected 1..64"),
    ({"ars": {"state_std_min": 0.0}}, "ars.state_std_min = 0.0: expected 0 < std <= 1"),
    ({"ars": {"state_std_min": float("nan")}}, "ars.state_std_min = nan: expected a finite number"),
    ({"algo": {"kind": "cem"}, "ars": {"normalize_states": True}},
     "ars.normalize_states = true: only for algo.kind = 'ars' \\(got 'cem'\\)"),
    ({"ars": {"features": ["theta", "speed"]}}, r"ars.features = \['theta', 'speed'\]: expected distinct names out of"),
    ({"ars": {"features": ["bias", "bias"]}}, r"ars.features = \['bias', 'bias'\]: expected distinct names"),
    ({"algo": {"kind": "cem"}, "ars": {"features": ["bias"]}}, r"ars.features = \['bias'\]: only for algo.kind = 'ars'"),
    ({"eval": {"collapse": -1.0}}, "eval.collapse = -1.0"),
    ({"eval": {"collapse": 0.5, "collapse_patience": 0}}, "eval.collapse_patience = 0: expected >= 1"),
    ({"algo": {"kind": "pg"}, "eval": {"collapse": 0.5}}, "eval.collapse = 0.5: only for algo.kind 'ars' or 'cem'"),
    ({"algo": {"kind": "cem"}, "cem": {"elites": 16}}, r"cem.elites = 16: expected 1..cem.population - 1 \(15\)"),
    ({"algo": {"kind": "cem"}, "cem": {"population": 1}}, "cem.population = 1: expected 2..1024"),
    ({"algo": {"kind": "cem"}, "cem": {"init_std": 0.0}}, "cem.init_std = 0.0: expected 0 < std <= 100"),
    ({"algo": {"kind": "cem"}, "cem": {"init_std": 1.0, "min_std": 2.0}}, "cem.min_std = 2.0: expected 0 < min_std"),
    ({"algo": {"kind": "cem", "rollback": 0.1}}, "algo.kind = 'cem' has no algo.rollback"),
    ({"ars": {"sigma": 1.0}}, r"\[ars\] unknown key\(s\) sigma"),
    ({"algo": {"max_kl": 0.1}}, "algo.kind = 'ars' has no algo.max_kl"),
    ({"policy": {"init": "random"}}, "policy.init_scale = 0.0: expected > 0 exactly when policy.init = 'random'"),
    ({"policy": {"init_scale": 0.5}}, "policy.init_scale = 0.5: expected > 0 exactly when"),
    ({"policy": {"init": "random", "init_scale": float("inf")}}, "policy.init_scale = inf: expected a finite number"),
    ({"policy": {"param": "feedback", "init": "beta", "init_beta": [0, 0, float("nan"), 0, 0, 0]}},
     "expected 6 finite numbers"),
]


@pytest.mark.parametrize("change,message", BAD)
def test_bad_options_are_refused_by_name(change, message):
    with pytest.raises(cfgmod.ConfigError, match=message.replace("(", r"\(").replace(")", r"\)")
                       if "\\" not in message else message):
        _cfg(**change)


def test_state_from_another_config_is_refused(tmp_path):
    trainer.train(_cfg(), tmp_path / "ars", quiet=True, stop_after=1)
    with pytest.raises(rundir.TrainError, match="different config"):
        trainer.train(_cfg(ars={"noise": 0.2}), tmp_path / "ars", quiet=True)
    with pytest.raises(rundir.TrainError, match="different config"):   # V1-t's state under V2-t
        trainer.train(_cfg(ars={"normalize_states": True}), tmp_path / "ars", quiet=True)
    pg = _cfg(algo={"kind": "pg", "entropy_coef": 0.0, "batch_episodes": 4})
    with pytest.raises(rundir.TrainError, match="different config"):
        trainer.train(pg, tmp_path / "ars", quiet=True)
    trainer.train(pg, tmp_path / "pg", quiet=True, stop_after=1)
    with pytest.raises(rundir.TrainError, match="different config"):
        trainer.train(_cfg(), tmp_path / "pg", quiet=True)


def test_non_finite_parameters_stop_the_run_and_keep_the_best(tmp_path, monkeypatch):
    real = ars.ars_step
    calls = []

    def exploding(*args, **kw):
        calls.append(1)
        step, sigma = real(*args, **kw)
        return (step * np.inf if len(calls) == 4 else step), sigma

    monkeypatch.setattr(ars, "ars_step", exploding)
    with pytest.raises(rundir.TrainError, match=r"iteration 3: the parameters diverged .* best validated weights"):
        trainer.train(_cfg(), tmp_path / "r", quiet=True)
    ck = rundir.load_checkpoint(tmp_path / "r" / "checkpoint.npz")
    assert int(ck["iteration"]) == 3 and np.all(np.isfinite(ck["params"]))
    doc = export.load_policy(tmp_path / "r")
    np.testing.assert_array_equal(export.weights_of(doc, "best"), ck["best_w"])


def test_a_collapsing_return_stops_the_run_and_keeps_the_best(tmp_path, monkeypatch):
    real = ars.ars_step
    calls = []

    def collapsing(deltas, *args, **kw):
        calls.append(1)
        step, sigma = real(deltas, *args, **kw)
        # The 7th step makes full negative torque (action 0) win every decision: the bucket never tilts.
        if len(calls) == 7:
            step = np.zeros(deltas.shape[1:])
            step[5, 0] = 1e3
        return step, sigma

    cfg = _cfg(iterations=20, eval={"collapse": 0.5, "collapse_patience": 2})
    assert trainer.train(cfg, tmp_path / "ok", quiet=True, stop_after=7).best_score > 0.05  # a best to fall from
    monkeypatch.setattr(ars, "ars_step", collapsing)
    with pytest.raises(rundir.TrainError, match=r"iteration 7: the return collapsed .* 2 evaluations in a row"):
        trainer.train(cfg, tmp_path / "r", quiet=True)
    ck = rundir.load_checkpoint(tmp_path / "r" / "checkpoint.npz")
    assert int(ck["iteration"]) == 8
    best = export.weights_of(export.load_policy(tmp_path / "r"), "best")
    np.testing.assert_array_equal(best, ck["best_w"])
    assert _v_target(best) > 0.1 and _v_target(ck["w"]) == 0.0


CEM = {"algo": {"kind": "cem", "entropy_coef": 0.0}, "cem": {"population": 16, "elites": 4, "init_std": 1.0}}


def test_cem_from_zero_learns_to_pour_the_toy_reproducibly_and_resumes(tmp_path):
    res = trainer.train(_cfg(iterations=12, **CEM), tmp_path / "r", quiet=True)
    assert _v_target(res.best_w) > 0.15 and res.best_score > 0.05
    trainer.train(_cfg(iterations=12, **CEM), tmp_path / "s", quiet=True, stop_after=5)
    again = trainer.train(_cfg(iterations=12, workers=2, **CEM), tmp_path / "s", quiet=True)
    np.testing.assert_array_equal(res.w, again.w)
    assert (tmp_path / "r" / "policy.json").read_bytes() == (tmp_path / "s" / "policy.json").read_bytes()
    with pytest.raises(rundir.TrainError, match="different config"):   # CEM's state under ARS's config
        trainer.train(_cfg(iterations=12), tmp_path / "s", quiet=True)


def test_cem_refits_to_the_elites_with_a_floor():
    cands = np.array([[0.0, 1.0], [2.0, 3.0], [4.0, 3.0], [9.0, 9.0]])
    mean, std = ars.cem_update(cands, np.array([1.0, 5.0, 5.0, -3.0]), elites=2, min_std=0.5)
    np.testing.assert_array_equal(mean, [3.0, 3.0])
    np.testing.assert_array_equal(std, [1.0, 0.5])


def test_pour_results_reach_finds_the_first_confirmed_iteration(tmp_path, monkeypatch):
    from pour.eval import results
    trainer.train(_cfg(iterations=20), tmp_path / "r", quiet=True)
    monkeypatch.setattr(results, "BAR_POURED_PCT", 15.0)   # bars the toy reaches
    monkeypatch.setattr(results, "BAR_SPILLED_PCT", 5.0)
    monkeypatch.setattr(results, "PREFILTER", (0.05, 1.0))
    got = results.reach(tmp_path / "r", 4)
    log = rundir.read_log(tmp_path / "r" / "log.csv")
    hist = rundir.load_checkpoint(tmp_path / "r" / "checkpoint.npz")["history_w"]
    env = envs.ToyEnv(11, 10, 10.0)

    def passes(i):
        ms = [env.rollout(hist[i], s, True).metrics for s in range(results.FIRST_SEED, results.FIRST_SEED + 4)]
        return 100 * np.mean([m["v_target"] for m in ms]) >= 15 and 100 * np.mean([m["v_spill"] for m in ms]) <= 5

    candidates = [i for i, r in enumerate(log) if float(r["eval_v_target"]) >= 0.05]
    first = next(i for i in candidates if passes(i))
    assert got["iteration"] == first and got["episodes"] == int(log[first]["episodes"]) == (first + 1) * 8
    row = results.reach_row("toy", [tmp_path / "r", tmp_path / "r"], 4)
    assert row["reached"] == 2 and row["episodes_median"] == got["episodes"] and row["budget_episodes"] == 160
    last = [env.rollout(hist[-1], s, True).metrics for s in range(results.FIRST_SEED, results.FIRST_SEED + 4)]
    assert row["final"]["poured_pct"] == pytest.approx(100 * np.mean([m["v_target"] for m in last]))
    assert row["final"]["episodes"] == 8   # the final weights of both runs, 4 held-out episodes each
    from pour.eval import plots
    png = tmp_path / "curves.png"
    plots.validation_curves({"toy": [tmp_path / "r", tmp_path / "r"]}, png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    monkeypatch.setattr(results, "BAR_POURED_PCT", 101.0)  # never reached: no number, said so
    never = results.reach_row("toy", [tmp_path / "r"], 4)
    assert never["reached"] == 0 and never["episodes_median"] is None
    assert "not reached" in results.reach_markdown([never], {"toy": {"poured_pct": 1.0, "spilled_pct": 0.0,
                                                             "spilled_pct_max": 0.0, "reversals": 0.0,
                                                             "reversals_max": 0.0, "finish_s": 1.0}}, 4)


def test_pour_results_reach_refuses_a_run_without_history(tmp_path):
    from pour.eval import results
    trainer.train(_cfg(iterations=2), tmp_path / "r", quiet=True)
    ck = rundir.load_checkpoint(tmp_path / "r" / "checkpoint.npz")
    del ck["history_w"]
    rundir.save_checkpoint(tmp_path / "r" / "checkpoint.npz", ck)
    with pytest.raises(ValueError, match="no W history"):
        results.reach(tmp_path / "r", 2)


@pytest.mark.parametrize("kind", ["ars", "cem"])
def test_python_m_trainer_runs_the_search_methods_as_the_entry_point_does(tmp_path, kind):
    """`python -m pour.train.trainer` runs the trainer as __main__, a second copy of the module: the methods
    come from the registry (pour.train.methods), not from a table the search module fills when imported, so
    that copy finds them too, and its run is the in-process one."""
    import subprocess
    import sys
    import tomllib

    doc = {**TOY, "iterations": 2, "algo": {**TOY["algo"], "kind": kind}}
    if kind == "cem":
        doc["ars"] = {}
        doc["cem"] = {"population": 4, "elites": 2}
    lines = []
    for k, v in doc.items():
        if not isinstance(v, dict):
            lines.append(f"{k} = {json.dumps(v)}")
    for k, v in doc.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{kk} = {json.dumps(vv)}" for kk, vv in v.items()]
    toml = tmp_path / "c.toml"
    toml.write_text("\n".join(lines) + "\n")
    r = subprocess.run([sys.executable, "-m", "pour.train.trainer", str(toml), "--out", str(tmp_path / "m"), "--quiet"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    trainer.train(cfgmod.from_dict(tomllib.loads(toml.read_text())), tmp_path / "in", quiet=True)
    assert (tmp_path / "m" / "policy.json").read_bytes() == (tmp_path / "in" / "policy.json").read_bytes()
