# SPDX-License-Identifier: MIT
"""The training distribution is written once, in configs/sim/randomised.cfg: the training configs, the
Gymnasium id and the robustness evaluation name it, and no other file of configs/ or tools/ states a width."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from pour import paths
from pour.sim import gym_ids, rigs
from pour.train import config

ROOT = Path(__file__).resolve().parents[2]
RIG_FILE = ROOT / "configs" / "sim" / "randomised.cfg"
# A rand_* key given a number that is not zero (the simulator's default, off), in any file's syntax:
# TOML and .cfg (rand_fill = 0.2), Python ("rand_fill": 0.2, rand_fill=0.2).
WIDTH = re.compile(r"""\brand_[a-z_]+["']?\s*[:=]\s*(?![0.]+(?![0-9.]))[0-9.]+""")


def test_the_rig_file_holds_the_training_distribution():
    rig = rigs.load("randomised")
    assert rig == {"rand_fill": 0.2, "rand_target_dx": 0.02, "rand_pivot_height": 0.02, "rand_motor": 0.15,
                   "rand_bucket_mass": 0.2, "rand_liquid": 0.2, "rand_sensor": 0.5}
    assert paths.data_file("randomised.cfg") == RIG_FILE


def test_no_other_file_states_a_width():
    found = []
    for path in sorted([*(ROOT / "configs").rglob("*"), *(ROOT / "tools" / "pour").rglob("*.py")]):
        if path.is_file() and path != RIG_FILE:
            for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if WIDTH.search(line):
                    found.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert found == []
    assert WIDTH.search('"rand_fill": 0.2') and WIDTH.search("rand_motor = 0.15") and WIDTH.search("rand_fill=0.2")
    assert not WIDTH.search("rand_fill = 0   # off") and not WIDTH.search("rand_fill = 0.0")


def test_the_training_configs_the_gym_id_and_the_robustness_evaluation_name_it():
    rig = rigs.load("randomised")
    tomls = sorted((ROOT / "configs" / "train").glob("*.toml"))
    named = [p.name for p in tomls if 'rig = "randomised"' in p.read_text(encoding="utf-8")]
    assert len(named) == 10 and "toy.toml" not in named
    for name in named:
        assert {k: v for k, v in config.load(ROOT / "configs" / "train" / name).env.options.items()
                if k.startswith("rand_")} == rig, name
    assert gym_ids.env_kwargs(gym_ids.IDS["pour/PourRandomised-v0"]) == {"options": rig}
    from pour.eval import robust_scale
    assert robust_scale.DEFAULT_RAND == rig


def test_a_key_set_by_the_rig_and_the_options_is_refused():
    with pytest.raises(config.ConfigError, match=r"\[env.options\] rand_fill: already set by \[env\] rig"):
        config.from_dict({"env": {"rig": "randomised", "options": {"rand_fill": 0.1}}})
    with pytest.raises(config.ConfigError, match=r"\[env\] rig: unknown rig 'wide': expected one of randomised"):
        config.from_dict({"env": {"rig": "wide"}})
    with pytest.raises(config.ConfigError, match=r"\[env\] rig = 3: expected a rig name"):
        config.from_dict({"env": {"rig": 3}})


@pytest.mark.parametrize("text", ["rand_fill 0.2\n", "rand_fill = wide\n", "rand_fill = 0.2\nrand_fill = 0.1\n",
                                  "# nothing\n"])
def test_a_bad_rig_file_is_refused_with_its_line(tmp_path, monkeypatch, text):
    bad = tmp_path / "bad.cfg"
    bad.write_text(text, encoding="utf-8")
    monkeypatch.setitem(rigs.RIGS, "bad", "bad.cfg")
    monkeypatch.setattr(paths, "data_file", lambda name: bad)
    with pytest.raises(rigs.RigError, match=re.escape(str(bad))):
        rigs.load("bad")
