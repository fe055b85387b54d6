# SPDX-License-Identifier: MIT
"""One tick driver: the Gymnasium stepper runs libpoursim's (poursim_stepper_*: episode_run's EpisodeRun and
EpisodeMeter), so its figures are the C rollout's, and Python holds no copy of the tick or the meter."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from pour.policy import weights_h
from pour.sim import adapter, envs, poursim

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _lib(build_dir, monkeypatch):
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))


def test_the_stepped_episode_s_figures_are_the_rollout_s():
    w = weights_h.parse_weights_h(ROOT / "policy" / "weights.h").w_float  # the shipped pour
    sim = envs.make_env("sim", 11, 10, 10.0)
    ep = sim.rollout(w, 5, True)
    st = envs.make_stepper("sim", 11, 10, 10.0, {"episode_s": 10.0})
    st.reset(5)
    for a in ep.actions:
        st.advance(float(sim.levels[a]), 10, int(a))
    m = st.metrics()
    assert ep.metrics["v_target"] > 0.5 and ep.metrics["finish_s"] > 0  # the figures are not trivially equal
    for key in ("v_target", "v_spill", "v_rotating", "finish_s", "reversals", "return"):
        assert m[key] == ep.metrics[key], key
    assert len(st.torques) == len(ep.actions) * 10


def test_python_holds_no_tick_or_meter_of_its_own():
    src = (ROOT / "tools" / "pour" / "sim" / "adapter.py").read_text(encoding="utf-8")
    assert not re.search(r"REVERSAL|\.gamma\b|_discount|self\.settled|0\.99\b|set_brake|world\.step\(", src)


def test_a_stepper_refuses_bad_use_by_name():
    world = poursim.World({"episode_s": 0.1})
    with pytest.raises(poursim.SimError, match="decision_period 0 outside 1..65535"):
        poursim.Stepper(world, poursim.default_reward(), 0)
    with pytest.raises(poursim.SimError, match="reward k_spill = -1 is out of range"):
        poursim.Stepper(world, poursim.Reward(1.0, -1.0, 0.9), 10)
    st = poursim.Stepper(world, poursim.default_reward(), 10)
    with pytest.raises(poursim.SimError, match="reset it first"):
        st.advance(0, 0.5, 10)
    st.reset(1)
    with pytest.raises(poursim.SimError, match="level nan"):
        st.advance(0, float("nan"), 10)
    assert isinstance(adapter.SimStepper({"episode_s": 0.1}, 10).stepper, poursim.Stepper)
