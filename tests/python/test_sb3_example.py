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
