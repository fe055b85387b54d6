# SPDX-License-Identifier: MIT
"""pour.examples.sb3_ppo: Stable-Baselines3's PPO on pour/Pour-v0 with a softmax-linear actor, exported to
weights.h. A short budget (2048 decisions: two PPO updates) checks the path, not the learning: the actor SB3
trained is exactly the exported W (the same action probabilities), the run is reproducible from its seed,
the header goes through pour-export's code and host_sim runs it, and bad input ends in a clear error.
The sb3 extra comes from ctest's set-up step py_setup_sb3 (scripts/setup.sh --with-sb3)."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import BUILD_DIR
from pour.examples import sb3_ppo
from pour.policy import linear, weights_h
from pour.sim import gym_env

STEPS = 2048


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The example's command line, as a user runs it: (run dir, header, its stdout)."""
    out = tmp_path_factory.mktemp("sb3") / "run"
    header = out / "weights.h"
    r = subprocess.run([sys.executable, "-m", "pour.examples.sb3_ppo", "--steps", str(STEPS), "--seed", "3",
                        "--out", str(out), "--header", str(header)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "PPO" in r.stderr and "2048/2048" in r.stderr  # progress with the time left, on stderr
    return out, header, r.stdout


def test_the_actor_is_the_exported_softmax_linear_policy(run):
    import torch
    from stable_baselines3 import PPO

    out, _, _ = run
    model = PPO.load(out / "sb3_model.zip", device="cpu")
    doc = json.loads((out / "policy.json").read_text())
    w = np.array(doc["w"])
    assert w.shape == (6, 11) and np.array_equal(w, sb3_ppo.linear_weights(model))
    assert np.abs(w).max() > 0  # trained from SB3's initial layer, not zeros
    obs = np.random.default_rng(0).random((500, 5)).astype(np.float32)
    with torch.no_grad():
        sb3_probs = model.policy.get_distribution(torch.as_tensor(obs)).distribution.probs.numpy()
    x = np.hstack([obs.astype(np.float64), np.ones((len(obs), 1))])
    np.testing.assert_allclose(linear.probs(w, x), sb3_probs, atol=1e-6)
    assert doc["n_actions"] == 11 and doc["decision_period_ms"] == 10 and doc["tau_max_nm"] == 20.0


def test_the_header_is_the_exporters_and_host_sim_runs_it(run, tmp_path):
    out, header, stdout = run
    assert f"{header}: exported" in stdout
    h = weights_h.parse_weights_h(header)
    w = np.array(json.loads((out / "policy.json").read_text())["w"])
    np.testing.assert_allclose(h.w_dequantized, w, atol=2.0 ** -h.w_frac_bits)
    # pour-export on the run writes the same bytes (one exporter).
    again = tmp_path / header.name  # the banner names the file
    r = subprocess.run([str(Path(sys.executable).parent / "pour-export"), str(out), "--out", str(again)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert again.read_bytes() == header.read_bytes()
    r = subprocess.run([str(BUILD_DIR / "bin" / "host_sim"), "--policy", str(header), "--seed", "1000001",
                        "--set", "episode_s=2", "--json", "--quiet"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["episodes"] == 1


def test_the_same_seed_trains_the_same_weights(run):
    out, _, _ = run
    w = sb3_ppo.train_linear(STEPS, seed=3)
    assert np.array_equal(w, np.array(json.loads((out / "policy.json").read_text())["w"]))


def test_an_actor_with_a_hidden_layer_is_refused():
    import gymnasium as gym
    from stable_baselines3 import PPO

    model = PPO("MlpPolicy", gym.make("pour/PourToy-v0"), device="cpu")  # SB3's default: two hidden layers
    with pytest.raises(sb3_ppo.ExampleError, match="not softmax-linear"):
        sb3_ppo.linear_weights(model)


@pytest.mark.parametrize("argv, message", [
    (["--steps", "0"], "steps = 0: expected at least 1"),
    (["--env", "pour/Nope-v0"], "Nope"),
    (["--header", "/nonexistent/dir/w.h"], "--header"),
    (["--init-header", "/nonexistent/w.h"], "cannot read"),
    (["--actor", "mlp"], "--actor mlp needs --like"),
    (["--actor", "tree"], "invalid choice: 'tree'"),
])
def test_bad_input_is_a_clear_error(tmp_path, argv, message):
    r = subprocess.run([sys.executable, "-m", "pour.examples.sb3_ppo", "--steps", "64", "--out",
                        str(tmp_path / "run"), *argv], capture_output=True, text=True, timeout=300)
    assert r.returncode != 0 and "Traceback" not in r.stderr and message in r.stderr, r.stderr


def test_without_the_extra_it_says_how_to_install_it(tmp_path):
    code = ("import sys; sys.modules['torch'] = None; from pour.examples import sb3_ppo; "
            f"sys.exit(sb3_ppo.main(['--steps', '64', '--out', {str(tmp_path / 'run')!r}]))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    assert "--with-sb3" in r.stderr


def test_started_from_the_shipped_header_it_still_pours(source_dir, tmp_path):
    """--init-header: the actor starts as the shipped W (to float32), so two short PPO updates later the
    exported policy still pours, where one started from SB3's initial layer pours nothing."""
    shipped = sb3_ppo.header_weights(source_dir / "policy" / "weights.h")
    out, header = tmp_path / "run", tmp_path / "run" / "weights.h"
    r = subprocess.run([sys.executable, "-m", "pour.examples.sb3_ppo", "--steps", str(STEPS), "--quiet",
                        "--init-header", str(source_dir / "policy" / "weights.h"), "--out", str(out),
                        "--header", str(header)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    doc = json.loads((out / "policy.json").read_text())
    assert doc["init_header"].endswith("weights.h")
    assert np.abs(np.array(doc["w"]) - shipped).max() < 0.05 * np.abs(shipped).max()  # moved a little
    r = subprocess.run([str(BUILD_DIR / "bin" / "host_sim"), "--policy", str(header), "--seed", "1000001",
                        "--episodes", "2", "--json", "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["poured_pct"] > 90


def test_set_and_read_linear_weights_round_trip():
    import gymnasium as gym

    model = sb3_ppo.make_model(gym.make("pour/PourToy-v0"), seed=1)
    w = np.random.default_rng(1).normal(size=(6, 11))
    sb3_ppo.set_linear_weights(model, w)
    np.testing.assert_allclose(sb3_ppo.linear_weights(model), w, rtol=1e-6)  # float32
    with pytest.raises(sb3_ppo.ExampleError, match="6 x 11"):
        sb3_ppo.set_linear_weights(model, w[:, :5])


LIKE = """seed = 1
iterations = 2
workers = 1
[policy]
n_actions = 11
decision_period_ms = 10
[algo]
kind = "pg"
[eval]
every = 1
episodes = 2
[env]
kind = "toy"
episode_s = 1.0
"""


@pytest.fixture(scope="module")
def like_run(tmp_path_factory):
    """--like: PPO on a training config's rig and validation, 6 episodes of 1 s, validated every 2."""
    d = tmp_path_factory.mktemp("like")
    (d / "toy.toml").write_text(LIKE)
    w = sb3_ppo.train_run(d / "toy.toml", d / "run", episodes=6, every=2, seed=4, n_steps=128, batch_size=64)
    return d / "run", w


def test_a_run_like_a_training_config_is_read_as_the_trainers_are(like_run):
    from pour.eval import plots, results
    from pour.sim import envs
    from pour.train import rundir

    run, w = like_run
    log = rundir.read_log(run / "log.csv")
    hist = rundir.load_checkpoint(run / "checkpoint.npz")["history_w"]
    assert [int(r["episodes"]) for r in log] == [2, 4, 6] and hist.shape == (3, 6, 11)
    doc = json.loads((run / "policy.json").read_text())
    assert np.array_equal(np.array(doc["w"]), hist[-1]) and np.array_equal(hist[-1], w)
    assert not np.array_equal(hist[0], hist[-1])   # PPO updated the actor (128 decisions an update)
    # Each row is the trainer's validation of that W: the same seeds (seed 4's), the same C rollouts.
    env = envs.ToyEnv(11, 10, 1.0)
    seeds = rundir.episode_seeds(4, rundir.STREAM_VALID, 0, 2)
    for row, wi in zip(log, hist):
        ms = [env.rollout(wi, s, True).metrics for s in seeds]
        assert float(row["eval_v_target"]) == pytest.approx(np.mean([m["v_target"] for m in ms]))
    best = int(np.argmax([float(r["eval_score"]) for r in log]))
    assert np.array_equal(np.array(doc["best_w"]), hist[best])
    assert results.reach(run, 2)["run"] == str(run)   # pour-results --reach reads it
    plots.validation_curves({"PPO": [run]}, run / "curves.png")


def test_a_diverging_ppo_run_stops_and_keeps_its_best(tmp_path, monkeypatch):
    (tmp_path / "toy.toml").write_text(LIKE)
    real, calls = sb3_ppo.linear_weights, []

    def nan_from_the_second(model):
        calls.append(1)
        return real(model) * (np.nan if len(calls) >= 2 else 1.0)

    monkeypatch.setattr(sb3_ppo, "linear_weights", nan_from_the_second)
    with pytest.raises(sb3_ppo.ExampleError, match="diverged after 4 episodes.*keeps the best validated weights"):
        sb3_ppo.train_run(tmp_path / "toy.toml", tmp_path / "run", episodes=6, every=2, seed=4)
    doc = json.loads((tmp_path / "run" / "policy.json").read_text())
    assert np.all(np.isfinite(doc["best_w"])) and doc["episodes"] == 2


@pytest.mark.parametrize("argv, message", [
    (["--episodes", "0"], "episodes = 0"),
    (["--episodes", "4", "--validate-every", "5"], "expected 1 <= every <= episodes"),
])
def test_bad_like_options_are_a_clear_error(tmp_path, argv, message):
    (tmp_path / "toy.toml").write_text(LIKE)
    r = subprocess.run([sys.executable, "-m", "pour.examples.sb3_ppo", "--like", str(tmp_path / "toy.toml"),
                        "--out", str(tmp_path / "run"), *argv], capture_output=True, text=True, timeout=300)
    assert r.returncode != 0 and "Traceback" not in r.stderr and message in r.stderr, r.stderr


def test_a_missing_or_bad_like_config_is_a_clear_error(tmp_path):
    (tmp_path / "bad.toml").write_text(LIKE.replace("episodes = 2", "episodes = 0"))
    for cfg, message in ((tmp_path / "nope.toml", "nope.toml"), (tmp_path / "bad.toml", "eval.episodes = 0")):
        r = subprocess.run([sys.executable, "-m", "pour.examples.sb3_ppo", "--like", str(cfg), "--episodes", "2",
                            "--validate-every", "1", "--out", str(tmp_path / "run")],
                           capture_output=True, text=True, timeout=300)
        assert r.returncode != 0 and "Traceback" not in r.stderr and message in r.stderr, r.stderr


def test_the_mlp_actor_in_numpy_is_sb3s_deterministic_action():
    """gym_env.mlp_actor on sb3_ppo.mlp_layers (how validation and pour-results run an MLP actor, without torch)
    picks SB3's own deterministic action."""
    import gymnasium as gym

    model = sb3_ppo.make_model(gym.make("pour/PourToy-v0"), seed=2, actor="mlp")
    layers = sb3_ppo.mlp_layers(model)
    assert [a.shape for a in layers] == [(5, 64), (64,), (64, 64), (64,), (64, 11), (11,)]
    with pytest.raises(sb3_ppo.ExampleError, match="not softmax-linear"):
        sb3_ppo.linear_weights(model)
    obs = np.random.default_rng(2).random((500, 5)).astype(np.float32)
    want, _ = model.predict(obs, deterministic=True)
    act = gym_env.mlp_actor(layers)
    assert [act(o) for o in obs] == list(want)
    assert len(set(want)) > 1   # the observations reach more than one action
    with pytest.raises(sb3_ppo.ExampleError, match="actor 'tree'"):
        sb3_ppo.make_model(gym.make("pour/PourToy-v0"), seed=2, actor="tree")


def test_an_mlp_run_is_read_through_the_env(tmp_path):
    """--actor mlp: every validation is the env's greedy run of that actor on the trainer's validation seeds,
    the actors are the checkpoint's history, and pour-results reads the run through the env (no W, no
    policy.json: pour-export refuses it)."""
    from pour.eval import results
    from pour.train import config as cfgmod
    from pour.train import rundir

    (tmp_path / "toy.toml").write_text(LIKE)
    run = tmp_path / "run"
    final = sb3_ppo.train_run(tmp_path / "toy.toml", run, episodes=6, every=2, seed=4, actor="mlp",
                              n_steps=128, batch_size=64)
    log = rundir.read_log(run / "log.csv")
    ck = rundir.load_checkpoint(run / "checkpoint.npz")
    assert [int(r["episodes"]) for r in log] == [2, 4, 6] and ck["history_mlp_0"].shape == (3, 5, 64)
    assert all(np.array_equal(ck[f"history_mlp_{k}"][-1], final[k]) for k in range(6))
    assert not np.array_equal(ck["history_mlp_4"][0], ck["history_mlp_4"][-1])   # PPO updated the actor
    cfg = cfgmod.load(tmp_path / "toy.toml")
    seeds = rundir.episode_seeds(4, rundir.STREAM_VALID, 0, 2)
    for i, row in enumerate(log):
        ev = sb3_ppo.mlp_validation(cfg, [ck[f"history_mlp_{k}"][i] for k in range(6)], seeds)
        assert float(row["eval_v_target"]) == pytest.approx(ev["eval_v_target"])
        assert float(row["eval_score"]) == pytest.approx(ev["eval_score"])
    best = int(np.argmax([float(r["eval_score"]) for r in log]))
    assert np.array_equal(ck["best_mlp_4"], ck["history_mlp_4"][best])
    doc = json.loads((run / "actor.json").read_text())
    assert doc["actor"] == "mlp" and doc["hidden"] == [64, 64] and not (run / "policy.json").exists()
    # pour-results: the final actor on the held-out seeds through the env, as the validation runs it.
    row = results.float_rows("PPO MLP", [run], 2, "last")
    assert "Gymnasium env" in row["how"]
    env = gym_env.PourEnv("toy", 11, 10, 10.0)
    want = [100 * gym_env.greedy_metrics(env, gym_env.mlp_actor(final), s)["v_target"]
            for s in range(results.FIRST_SEED, results.FIRST_SEED + 2)]
    assert row["poured_pct"] == pytest.approx(np.mean(want))
    assert results.reach(run, 2)["run"] == str(run)
    r = subprocess.run([str(Path(sys.executable).parent / "pour-export"), str(run), "--out", str(tmp_path / "w.h")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode != 0 and "policy.json" in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_an_mlp_run_with_a_broken_description_is_a_clear_error(tmp_path):
    from pour.eval import results

    (tmp_path / "toy.toml").write_text(LIKE)
    run = tmp_path / "run"
    sb3_ppo.train_run(tmp_path / "toy.toml", run, episodes=2, every=2, seed=4, actor="mlp", n_steps=128,
                      batch_size=64)
    (run / "actor.json").write_text("{}")
    with pytest.raises(ValueError, match="actor.json: not an MLP actor's description"):
        results.reach(run, 2)
