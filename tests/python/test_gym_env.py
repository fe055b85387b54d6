# SPDX-License-Identifier: MIT
"""The Gymnasium environment (toy backend here; tests/python/test_sim_train.py runs the simulator one)."""
import csv
import json
import subprocess

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pour.sim.gym_env  # noqa: F401  (registers the ids)
from pour import functions
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


POUR_IDS = sorted(i for i in gym.registry if i.startswith("pour/"))


def test_the_three_ids_are_registered():
    assert POUR_IDS == ["pour/Pour-v0", "pour/PourRandomised-v0", "pour/PourToy-v0"]


@pytest.mark.parametrize("env_id", POUR_IDS)
def test_every_registered_id_passes_the_checker_in_each_render_mode_it_advertises(env_id):
    env = gym.make(env_id)
    check_env(env.unwrapped, skip_render_check=False)
    for mode in env.unwrapped.metadata["render_modes"]:
        made = gym.make(env_id, render_mode=mode)
        check_env(made.unwrapped, skip_render_check=False)
        made.reset(seed=1)
        frame = made.render()
        assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3


def test_the_toy_advertises_no_render_mode_and_refuses_one():
    assert gym.make("pour/PourToy-v0").unwrapped.metadata["render_modes"] == []
    with pytest.raises(envs.EnvError, match="only the 'sim' backend"):
        pour.sim.gym_env.PourEnv("toy", render_mode="rgb_array")


@pytest.mark.parametrize("backend", ["toy", "sim"])
@pytest.mark.parametrize("options, why", [
    ({"rig": {"no_such_key": 1}}, "no_such_key"),
    ({"rig": {"drive": 7}}, "drive"),
    ({"rig": [1, 2]}, "expected a dict"),
    ({"wind": 3}, "the only option is 'rig'"),
])
def test_a_refused_reset_changes_nothing(backend, options, why):
    env = pour.sim.gym_env.PourEnv(backend, episode_s=1.0)
    fresh = pour.sim.gym_env.PourEnv(backend, episode_s=1.0)
    env.reset(seed=3)
    fresh.reset(seed=3)
    try:
        env.reset(seed=5, options=options)
    except envs.EnvError as e:
        assert why in str(e)
    else:
        assert backend == "toy", "the simulator accepted " + repr(options)
        return
    # The env goes on as if the refused call had not been made: its generator, its options, its plant.
    obs, info = env.reset()
    want_obs, want_info = fresh.reset()
    assert info == want_info and np.array_equal(obs, want_obs)
    assert env.reset(seed=9, options={})[0].tolist() == fresh.reset(seed=9)[0].tolist()
    for a in (10, 10, 3):
        got, want = env.step(a), fresh.step(a)
        assert np.array_equal(got[0], want[0]) and got[1:4] == want[1:4]


def test_a_bad_seed_is_refused_before_anything_changes():
    env, fresh = pour.sim.gym_env.PourEnv("toy"), pour.sim.gym_env.PourEnv("toy")
    env.reset(seed=2)
    fresh.reset(seed=2)
    for bad in (-1, 2**32, 1.5, "3"):
        with pytest.raises(envs.EnvError, match="seed"):
            env.reset(seed=bad)
    assert env.reset()[1] == fresh.reset()[1]


def test_a_fault_terminates_the_episode_and_it_is_no_success():
    """The encoder wired backwards (drive_fault 3) under full torque: the core faults and stops the bucket;
    the env ends the episode at that step (terminated, not truncated), naming the faults."""
    env = pour.sim.gym_env.PourEnv("sim", episode_s=2.0, options={"drive": 1, "drive_fault": 3})
    env.reset(seed=1)
    terminated = truncated = False
    n = 0
    while not (terminated or truncated):
        _, _, terminated, truncated, info = env.step(10)
        n += 1
    assert terminated and not truncated and n < env.max_decisions
    assert info["faults"] != 0 and info["is_success"] is False
    assert info["fault_names"] == functions.fault_names(info["faults"]) and info["fault_names"]
    with pytest.raises(gym.error.ResetNeeded):
        env.step(0)


def test_is_success_says_whether_the_targets_were_met():
    env = gym.make("pour/PourToy-v0", episode_s=2.0)
    env.reset(seed=1)
    truncated = False
    while not truncated:
        _, _, terminated, truncated, info = env.step(0)  # no torque: nothing poured
        assert not terminated and ("is_success" in info) == truncated
    assert info["is_success"] is False and info["v_target"] < 0.95


def test_the_shipped_policys_pour_is_a_success(tmp_path, build_dir, source_dir):
    """host_sim's decisions of the shipped policy, replayed in pour/Pour-v0: the same episode, which meets
    the targets by host_sim's own figures, ends truncated with is_success."""
    seed, steps = 1000001, tmp_path / "steps.csv"
    r = subprocess.run([str(build_dir / "bin" / "host_sim"), "--policy", str(source_dir / "policy" / "weights.h"),
                        "--seed", str(seed), "--json", "--quiet", "--csv", str(steps)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    want = json.loads(r.stdout)
    assert want["poured_pct"] >= 95 and want["spilled_pct"] <= 3 and 0 <= want["finish_s"] <= 8
    with steps.open() as f:
        actions = [int(row["action"]) for row in list(csv.DictReader(f))[::10]]
    env = gym.make("pour/Pour-v0")
    env.reset(seed=seed)
    for k, a in enumerate(actions):
        _, _, terminated, truncated, info = env.step(a)
        assert not terminated and truncated == (k == len(actions) - 1)
    assert info["is_success"] is True and round(100 * info["v_target"], 3) == want["poured_pct"]
