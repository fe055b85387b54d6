# SPDX-License-Identifier: MIT
"""One control pipeline (issue 24's bar): the same seeds through host_sim (the firmware core with its
fixed-point policy), the C rollout (the trainer's float policy) and the Gymnasium env (an agent's actions)
give bit-identical torques, because all three run the firmware's own pour_control_update / decision /
pour_control_shape. host_sim's and the rollout's decisions are replayed through the Gymnasium env."""
import csv
import subprocess

import numpy as np
import pytest

import pour.sim.envs
import pour.sim.gym_env
from pour.policy import fixedpoint as fp
from pour.policy import linear, weights_h
from pour.sim import episode, poursim

EPISODE_S = 2.0
PERIOD = 10
SEEDS = (3, 8)


def host_sim_run(build_dir, source_dir, tmp_path, seed, opts=None):
    """host_sim --policy policy/weights.h: per step the action in force and the core's torque, Q15."""
    out = tmp_path / f"steps_{seed}.csv"
    sets = [a for k, v in {"episode_s": EPISODE_S, **(opts or {})}.items() for a in ("--set", f"{k}={v}")]
    subprocess.run([str(build_dir / "bin" / "host_sim"), "--policy", str(source_dir / "policy" / "weights.h"),
                    "--seed", str(seed), *sets, "--quiet", "--csv", str(out)],
                   check=True, capture_output=True, timeout=300)
    with out.open() as f:
        rows = list(csv.DictReader(f))
    # %.6f of a Q15 fraction names the Q15 value exactly (1/32768 > 1e-6).
    torques = np.array([round(float(r["torque_frac"]) * 32768) for r in rows], dtype=np.int64)
    actions = np.array([int(r["action"]) for r in rows])
    return torques, actions[::PERIOD]


def gym_replay(seed, actions, opts=None):
    """The Gymnasium env, reset(seed=seed) as host_sim --seed seed, fed one action per decision: the core's
    torque of every tick, Q15."""
    env = pour.sim.gym_env.PourEnv("sim", n_actions=11, decision_period_ms=PERIOD, episode_s=EPISODE_S,
                                   options=opts)
    env.reset(seed=seed)
    for a in actions:
        env.step(int(a))
    return np.array(env._plant.torques, dtype=np.int64)


def rollout_run(header, seed, opts=None):
    """poursim_rollout with the float policy of the header (greedy): its torques, Q15, and its actions."""
    world = poursim.World({"episode_s": EPISODE_S, **(opts or {})})
    pol = poursim.Policy(header.w_dequantized, header.levels_q15 / 32768.0, header.decision_period_ms,
                         episode.THETA_MIN_RAD, episode.THETA_MAX_RAD, episode.OMEGA_MAX_RAD_S, True, 0.0)
    ro = world.rollout(pol, seed, record_steps=True)
    assert ro.metrics["faults"] == 0  # a plain pour: the core stayed in RUN
    return np.round(ro.step_torque * 32768).astype(np.int64), ro.actions


@pytest.fixture
def header(source_dir):
    h = weights_h.parse_weights_h(source_dir / "policy" / "weights.h")
    # The env's levels are the shipped policy's: evenly spaced, rounded as the firmware rounds.
    assert h.n_actions == 11 and h.decision_period_ms == PERIOD
    assert [fp.float_to_q15(x) for x in linear.action_levels(11)] == list(h.levels_q15)
    return h


@pytest.mark.parametrize("seed", SEEDS)
def test_host_sim_rollout_and_gym_env_give_bit_identical_torques(build_dir, source_dir, tmp_path, header, seed):
    h_torque, h_actions = host_sim_run(build_dir, source_dir, tmp_path, seed)
    r_torque, r_actions = rollout_run(header, seed)
    assert len(h_torque) == len(r_torque) == int(EPISODE_S * 1000)
    assert np.count_nonzero(h_torque) > 0 and len(set(h_actions)) > 1  # a real pour, several levels

    np.testing.assert_array_equal(gym_replay(seed, h_actions), h_torque)
    np.testing.assert_array_equal(gym_replay(seed, r_actions), r_torque)

    # On these seeds the float and the fixed-point policy decide alike every time (pour-eval agree measures
    # the rate elsewhere), so the three runs are one run.
    np.testing.assert_array_equal(r_actions, h_actions)
    np.testing.assert_array_equal(r_torque, h_torque)


def test_the_fill_schedule_runs_alike_in_all_three(build_dir, source_dir, tmp_path, header):
    """A rig whose file asks for the envelope's fill schedule (here any fill above 5 L, so the nominal 10 L
    one; its knee 33.9° - 3°) configures the firmware the same way in host_sim, the C rollout and the
    Gymnasium env, from the rig drawn for the episode: bit-identical torques again, and not the unscheduled
    run's (the schedule slows this pour)."""
    opts = {"fill_schedule_l": 5.0}
    seed = SEEDS[0]
    h_torque, h_actions = host_sim_run(build_dir, source_dir, tmp_path, seed, opts)
    r_torque, r_actions = rollout_run(header, seed, opts)
    np.testing.assert_array_equal(gym_replay(seed, h_actions, opts), h_torque)
    np.testing.assert_array_equal(gym_replay(seed, r_actions, opts), r_torque)
    np.testing.assert_array_equal(r_torque, h_torque)
    plain, _ = host_sim_run(build_dir, source_dir, tmp_path, seed)
    assert not np.array_equal(plain, h_torque)


def test_the_env_measures_an_episode_as_the_c_rollout_does():
    """gym_env.greedy_metrics (how pour-results evaluates an actor poursim_rollout cannot run, such as an MLP)
    gives the C rollout's figures for the same greedy policy: volumes, finish time, torque reversals and the
    discounted return. The policy is a stiff feedback hold (u = -8 θn - 4.5 ωn + 8.9) that chatters over three
    torque levels, so the reversal count is not zero."""
    levels = linear.action_levels(11)
    beta = np.array([-8.0, -4.5, 0.0, 0.0, 0.0, 8.9])
    bias = np.zeros(6)
    bias[5] = 1.0
    w = 50.0 * (2.0 * np.outer(beta, levels) - np.outer(bias, levels ** 2))
    env = pour.sim.gym_env.PourEnv("sim", n_actions=11, decision_period_ms=PERIOD, episode_s=EPISODE_S)
    sim = pour.sim.envs.make_env("sim", 11, PERIOD, EPISODE_S)
    act = lambda obs: int(np.argmax(np.append(obs.astype(np.float64), 1.0) @ w))  # noqa: E731
    for seed in SEEDS:
        want = sim.rollout(w, seed, True).metrics
        got = pour.sim.gym_env.greedy_metrics(env, act, seed)
        assert want["reversals"] > 5 and got["reversals"] == want["reversals"]
        for key in ("v_target", "v_spill", "finish_s"):
            assert got[key] == want[key], key
        assert got["return"] == pytest.approx(want["return"], rel=1e-12)
