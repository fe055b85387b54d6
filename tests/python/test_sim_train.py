# SPDX-License-Identifier: MIT
"""The trainer, the Gymnasium env and the shipped policy on the Box2D simulator (libpoursim)."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pour.sim.gym_env
from pour.eval import evaluate
from pour.policy import weights_h
from pour.sim import adapter, envs, poursim
from pour.train import config as cfgmod
from pour.train import rundir, trainer

SRC = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def test_sim_gym_env_passes_the_checker():
    env = pour.sim.gym_env.PourEnv("sim", episode_s=0.1)
    check_env(env, skip_render_check=True)


def test_sim_gym_env_follows_the_gymnasium_conventions():
    """rgb_array rendering, max_episode_steps, the randomised rig's id, rig options at reset, refusals."""
    import gymnasium as gym
    env = gym.make("pour/Pour-v0", render_mode="rgb_array", episode_s=0.1)
    assert env.spec.max_episode_steps == 1000
    check_env(env.unwrapped)
    env.reset(seed=3)
    before = env.render()
    for _ in range(10):
        env.step(10)
    after = env.render()
    assert before.shape == (240, 320, 3) and before.dtype == np.uint8
    assert np.any(before != after)  # the bucket tilted, the liquid moved
    rand = gym.make("pour/PourRandomised-v0", episode_s=0.1)
    rand.reset(seed=3)
    assert rand.unwrapped._plant.world.episode_config()["fill_depth"] != \
        env.unwrapped._plant.world.episode_config()["fill_depth"]  # the seed's draw of the rig
    env.reset(seed=3, options={"rig": {"fill_depth": 0.15}})
    assert env.unwrapped._plant.world.config.fill_depth == 0.15
    with pytest.raises(envs.EnvError, match="the only option is 'rig'"):
        env.reset(options={"fill_depth": 0.15})
    with pytest.raises(envs.EnvError, match="simulator option no_such_key"):
        env.reset(options={"rig": {"no_such_key": 1.0}})
    with pytest.raises(envs.EnvError, match="render_mode 'human'"):
        pour.sim.gym_env.PourEnv("sim", render_mode="human")
    with pytest.raises(envs.EnvError, match="seed 4294967296"):
        env.reset(seed=2**32)


def test_gym_steps_reproduce_the_c_rollout():
    """Tick-by-tick stepping (the firmware's pipeline, in C through pour.core) and the C whole-episode
    rollout agree exactly."""
    sim = envs.make_env("sim", 11, 10, 0.6)
    w = np.zeros((6, 11))
    w[0, :] = np.linspace(30, -30, 11)  # torque falls as theta grows, so actions change along the way
    w[5, :] = np.linspace(-2, 2, 11)
    ep = sim.rollout(w, 31, True)
    env = pour.sim.gym_env.PourEnv("sim", episode_s=0.6)
    env._plant.reset(31)
    env._k, env._started = 0, True
    assert isinstance(env._plant.stepper, poursim.Stepper)  # libpoursim's tick driver, none in Python
    xs, rewards = [env._plant.features()], []
    for a in ep.actions:
        obs, r, term, trunc, info = env.step(int(a))
        xs.append(env._plant.features())
        rewards.append(r)
    np.testing.assert_array_equal(np.array(xs[:-1]), ep.x)
    np.testing.assert_array_equal(rewards, ep.rewards)
    assert trunc and len(set(ep.actions.tolist())) > 1


def test_one_training_iteration_on_the_simulator(tmp_path):
    beta = [0.0, 0.0, 0.0, 0.0, 0.0, 0.9]  # forward torque: the liquid moves within the short episode
    cfg = cfgmod.from_dict({"seed": 1, "iterations": 1, "workers": 2,
                            "policy": {"n_actions": 11, "param": "feedback", "init": "beta", "init_beta": beta},
                            "algo": {"batch_episodes": 2}, "eval": {"every": 1, "episodes": 2},
                            "env": {"kind": "sim", "episode_s": 0.8}})
    res = trainer.train(cfg, tmp_path / "r", quiet=True)
    w0 = rundir.weights(cfg, np.array(beta))
    assert res.iterations == 1 and not np.array_equal(res.w, w0)
    assert (tmp_path / "r" / "policy.json").exists()


def test_missing_library_gives_a_clear_error(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('iterations = 1\n[env]\nkind = "sim"\n')
    env = dict(os.environ, POUR_SIM_LIB=str(tmp_path / "nowhere" / "libpoursim.so"))
    r = subprocess.run([sys.executable, "-m", "pour.train.trainer", str(cfg), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 2
    assert "pour-train: error: cannot load the simulator library" in r.stderr and "nowhere" in r.stderr
    assert "Traceback" not in r.stderr


def test_bad_simulator_option_is_named():
    with pytest.raises(envs.EnvError, match="simulator option k_spil"):
        envs.make_env("sim", 11, 10, 1.0, {"k_spil": 3})


def test_shipped_policy_quantised_agrees_with_float_on_held_out_states():
    hdr = weights_h.parse_weights_h(SRC / "policy" / "weights.h")
    assert hdr.w_float is not None and hdr.n_actions == 11
    sim = envs.make_env("sim", hdr.n_actions, hdr.decision_period_ms, 10.0)
    xs = np.concatenate([sim.rollout(hdr.w_float, s, True).x for s in evaluate.held_out_seeds(4)])
    assert evaluate.agreement(hdr.w_float, hdr, xs) >= 0.99
