# SPDX-License-Identifier: MIT
"""The Gymnasium environment (toy backend here; tests/python/test_sim_train.py runs the simulator one)."""
import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pour.sim.gym_env  # noqa: F401  (registers the ids)
from pour.sim import envs


def test_toy_env_passes_the_gymnasium_checker():
    env = gym.make("pour/PourToy-v0", episode_s=1.0)
    check_env(env.unwrapped, skip_render_check=True)


def test_reset_with_seed_is_reproducible_and_episode_truncates_at_10_s():
    env = gym.make("pour/PourToy-v0")
    runs = []
    for _ in range(2):
        obs, info = env.reset(seed=4)
        rng = np.random.default_rng(0)
        total, n, trunc = 0.0, 0, False
        while not trunc:
            obs, r, term, trunc, info = env.step(int(rng.integers(6, 11)))
            assert not term and obs.dtype == np.float32 and env.observation_space.contains(obs)
            total += r
            n += 1
        runs.append((total, n, info["v_target"] + info["v_spill"]))
    assert runs[0] == runs[1]
    assert runs[0][1] == 1000 and runs[0][2] > 0.5  # forward torque moves the liquid out


def test_step_matches_the_trainer_rollout():
    """Same plant, same seed, same actions: the env's rewards are the rollout's per-decision rewards."""
    w = np.zeros((6, 11))
    w[5, 8] = 3.0  # greedy: always level 8
    ep = envs.ToyEnv(11, 10, 2.0).rollout(w, 77, True)
    env = pour.sim.gym_env.PourEnv("toy", episode_s=2.0)
    env._plant.reset(77)
    env._k, env._started = 0, True
    rewards = [env.step(int(a))[1] for a in ep.actions]
    np.testing.assert_allclose(rewards, ep.rewards, rtol=0, atol=0)


def test_bad_arguments_and_actions_are_refused():
    with pytest.raises(envs.EnvError, match="backend 'mujoco'"):
        pour.sim.gym_env.PourEnv("mujoco")
    with pytest.raises(envs.EnvError, match="n_actions = 1"):
        pour.sim.gym_env.PourEnv("toy", n_actions=1)
    env = pour.sim.gym_env.PourEnv("toy")
    with pytest.raises(gym.error.ResetNeeded):
        env.step(0)
    env.reset(seed=1)
    with pytest.raises(gym.error.InvalidAction):
        env.step(11)
