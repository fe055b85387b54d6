# SPDX-License-Identifier: MIT
"""tools/pour/sim/poursim.py: the ctypes binding of libpoursim."""
import ctypes as C
import os
import subprocess
import sys

import numpy as np
import pytest

from pour.sim import poursim


@pytest.fixture(autouse=True)
def _lib(build_dir, monkeypatch):
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))


def small_policy(greedy=False):
    lv = poursim.uniform_levels(5)
    w = np.zeros((6, 5))
    w[0], w[2], w[5] = -3 * lv, 2 * lv, lv  # tilt while full and upright
    return poursim.Policy(w=w, levels=lv, decision_period=10, greedy=greedy)


def test_default_config_has_the_documented_scene():
    c = poursim.default_config()
    assert tuple(c) == poursim.config_keys() and len(c) > 40
    assert c["n_particles"] == 150 and c["bucket_inner_width"] == 0.24 and c["bucket_height"] == 0.33
    assert c["bucket_wall"] == 0.005 and c["dt"] == 0.001 and c["episode_s"] == 10.0
    assert c["restitution_liquid"] == 0.5 and c["restitution_wall"] == 0.1


def test_rig_keys_and_readings_cross_the_binding_with_the_c_layout():
    # Values the C side sets land in the right Python fields only if the layouts agree field by field.
    c = poursim.default_config()
    assert (c["motor_peak_torque"], c["motor_no_load_speed"], c["gear_ratio"]) == (25.0, 21.0, 20.0)
    assert (c["command_latency_ticks"], c["encoder_bits"], c["scale_rate_hz"]) == (1, 17, 80.0)
    assert c["rand_sensor"] == 0.0 and c["seed"] == 1
    with poursim.World(seed=3) as w:
        o = w.observe()
        assert o.encoder in (0, (1 << 17) - 1) or o.encoder < 50 or o.encoder > (1 << 17) - 50
        assert 7000 < o.scale_rotating_g < 14000 and abs(o.scale_target_g) < 500  # 10.3 kg of agitated liquid
        w.step(1.0)
        o = w.step(1.0)
        assert o.torque == 20.0 and 19.0 < o.motor_torque <= 20.0  # the command of the step before, at speed
        assert o.encoder == round(o.theta * (1 << 17) / (2 * np.pi))
    with poursim.World({"rand_fill": 0.2, "rand_motor": 0.15}, seed=5) as w:
        e = w.episode_config()
        assert e["fill_depth"] != c["fill_depth"] and abs(e["fill_depth"] / c["fill_depth"] - 1) <= 0.2
        assert abs(e["motor_peak_torque"] / 25.0 - 1) <= 0.15 and e["rand_fill"] == 0.2
    d = poursim.measure_drive()
    assert d["latency_ticks"] == 1 and d["inertia_measured"] == pytest.approx(d["inertia_expected"], rel=0.01)
    with pytest.raises(poursim.SimError, match="encoder_bits"):
        poursim.make_config({"encoder_bits": 40})


def test_config_keys_come_from_the_library_with_their_declaration(tmp_path):
    keys = poursim.describe()
    assert keys["command_latency_ticks"] == poursim.KeyInfo(True, 1.0, 100.0, 1.0, "steps", keys["command_latency_ticks"].doc)
    assert not keys["tau_max"].integer and keys["tau_max"].unit == "N m" and keys["tau_max"].doc
    assert {k: i.default for k, i in keys.items()} == poursim.default_config()
    cfg = poursim.make_config({"tau_max": 12.5, "n_particles": 120})
    assert cfg["tau_max"] == 12.5 and cfg.tau_max == 12.5 and cfg["n_particles"] == 120
    assert isinstance(cfg["n_particles"], int) and isinstance(cfg["dt"], float)
    with pytest.raises(AttributeError):
        cfg.no_such_key
    cfg.write(tmp_path / "sim.cfg")
    assert poursim.make_config(path=tmp_path / "sim.cfg").as_dict() == cfg.as_dict()


def test_bad_config_key_or_value_raises_naming_it():
    with pytest.raises(poursim.SimError, match="no_such_key"):
        poursim.make_config({"no_such_key": 1})
    with pytest.raises(poursim.SimError, match="unknown config key 'gamma'"):
        poursim.make_config({"gamma": 0.9})  # the reward's, not the world's
    with pytest.raises(poursim.SimError, match="gamma"):
        poursim.reward_from({"gamma": 2.0})
    with pytest.raises(poursim.SimError, match="cannot read config file"):
        poursim.make_config(path="/nonexistent/sim.cfg")


def test_world_steps_and_accounts_for_every_circle():
    with poursim.World(seed=2) as w:
        o0 = w.observe()
        assert o0.step == 0 and o0.v_rotating == 1.0
        for _ in range(300):
            o = w.step(1.0)
        assert o.step == 300 and o.theta > 0.3
        xy, r = w.particles()
        assert xy.shape == (150, 2) and r.shape == (150,)
        reg = w.regions()
        assert np.bincount(reg, minlength=4).sum() == 150
        assert o.v_rotating == pytest.approx(np.mean(reg == 0))
        with pytest.raises(poursim.SimError, match="finite"):
            w.step(float("nan"))


def test_rollout_arrays_and_determinism():
    pol = small_policy()
    with poursim.World({"episode_s": 2.0}) as w:
        a = w.rollout(pol, seed=4, record_steps=True)
        b = w.rollout(pol, seed=4)
    assert a.features.shape == (200, 6) and a.actions.shape == (200,) and a.probs.shape == (200, 5)
    assert a.step_rewards.shape == (2000,)
    assert np.all(a.features[:, 5] == 1.0)
    assert np.all((a.features >= 0) & (a.features <= 1))
    assert np.allclose(a.probs.sum(axis=1), 1.0)
    assert a.rewards.sum() == pytest.approx(a.reward_sum) == pytest.approx(a.step_rewards.sum())
    assert np.array_equal(a.actions, b.actions) and a.ret == b.ret


def test_rollout_runs_as_many_steps_as_the_world():
    # 12.5 ms at 1 ms steps: the world says done at the first t >= episode_s - dt/2, after 12 steps; the
    # per-step arrays hold exactly those, as stepping the world by hand does.
    with poursim.World({"episode_s": 0.0125}) as w:
        r = w.rollout(small_policy(), seed=2, record_steps=True)
        w.reset(2)
        steps = 0
        o = w.observe()
        while not o.done:
            o = w.step(0.0)
            steps += 1
    assert steps == 12
    assert r.step_rewards.shape == (12,) and r.step_theta.shape == (12,)


def test_bad_policy_shape_raises():
    with pytest.raises(poursim.SimError, match="shape"):
        poursim.Policy(w=np.zeros((5, 11)), levels=poursim.uniform_levels(11))._struct()
    with pytest.raises(poursim.SimError):
        with poursim.World({"episode_s": 0.1}) as w:
            w.rollout(poursim.Policy(w=np.zeros((6, 3)), levels=np.array([-2.0, 0, 1])), 1)


def _load_in_subprocess(lib_path):
    code = ("from pour.sim import poursim\ntry:\n    poursim.load_library()\n"
            "except poursim.SimError as e:\n    print('SimError:', e)\n")
    env = dict(os.environ, POUR_SIM_LIB=str(lib_path))
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)


def test_missing_library_gives_a_clear_error(tmp_path):
    r = _load_in_subprocess(tmp_path / "nope.so")
    assert r.returncode == 0 and "SimError: libpoursim.so not found" in r.stdout


def test_library_that_fails_to_load_gives_a_clear_error(tmp_path):
    bad = tmp_path / "libpoursim.so"
    bad.write_text("not a shared library")
    r = _load_in_subprocess(bad)
    assert r.returncode == 0 and "failed to load" in r.stdout


def test_reward_and_normalisation_are_the_policys_not_the_worlds():
    assert "k_spill" not in poursim.config_keys() and "obs_omega_max" not in poursim.config_keys()
    assert poursim.default_reward() == poursim.Reward(1.0, 5.0, 0.9995)
    opts = {"k_spill": 10.0, "tau_max": 15.0}
    assert poursim.reward_from(opts) == poursim.Reward(1.0, 10.0, 0.9995) and opts == {"tau_max": 15.0}
    lv = poursim.uniform_levels(5)
    with poursim.World({"episode_s": 1.0}) as w:
        base = w.rollout(small_policy(greedy=True), seed=4, record_steps=True)
        pol = small_policy(greedy=True)
        pol.reward = poursim.Reward(2.0, 0.0, 1.0)
        ro = w.rollout(pol, seed=4, record_steps=True)
    assert np.array_equal(base.step_theta, ro.step_theta)  # the reward does not touch the world
    assert ro.step_rewards[-1] == pol.reward.step(ro.poured, ro.spilled) == 2.0 * ro.poured
    assert ro.ret == pytest.approx(ro.reward_sum) and lv.size == 5


def test_python_features_equal_the_c_normalisation_bit_for_bit():
    from pour.policy import linear
    rng = np.random.default_rng(11)
    for _ in range(2000):
        norm = (float(rng.uniform(-0.2, 0.2)), float(rng.uniform(1.0, 3.0)), float(rng.uniform(0.5, 8.0)))
        state = (float(rng.uniform(-0.5, 3.2)), float(rng.uniform(-10, 10)), *map(float, rng.uniform(-0.1, 1.1, 3)))
        assert np.array_equal(linear.features(*state, *norm), poursim.features(*norm, *state))


def test_every_record_class_has_the_size_of_its_c_record():
    lib = poursim.load_library()
    for py_name, c_name in poursim.RECORDS.items():
        assert C.sizeof(getattr(poursim, py_name)) == lib.poursim_sizeof(c_name.encode()), c_name
    assert lib.poursim_sizeof(b"poursim_config_t") == 0  # a handle, never mirrored
