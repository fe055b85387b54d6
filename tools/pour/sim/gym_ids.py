# SPDX-License-Identifier: MIT
"""pour's Gymnasium ids, declared once: pour.sim.gym_env registers them when it is imported, and so does the
installed package's start-up hook (_pour_gymnasium) as soon as a program imports gymnasium. Registration
is lazy: the entry point is a string, so gymnasium imports pour.sim.gym_env (and opens libpoursim) only
when an id is made."""
from __future__ import annotations

from typing import Any

ENTRY_POINT = "pour.sim.gym_env:PourEnv"

# id -> PourEnv keyword arguments, "rig" naming the rig distribution (pour.sim.rigs: configs/sim/<rig>.cfg)
# whose keys become the env's options; pour/PourRandomised-v0 is the one training randomises over.
# max_episode_steps (MAX_EPISODE_STEPS): decisions in the default 10 s episode at the default 10 ms period.
IDS: dict[str, dict[str, Any]] = {
    "pour/Pour-v0": {},
    "pour/PourRandomised-v0": {"rig": "randomised"},
    "pour/PourToy-v0": {"backend": "toy"},
}
MAX_EPISODE_STEPS = 1000


def register_all() -> None:
    """Registers every id that gymnasium's registry does not hold yet (so a second call changes nothing)."""
    import gymnasium as gym

    for env_id, kwargs in IDS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=ENTRY_POINT, max_episode_steps=MAX_EPISODE_STEPS,
                         kwargs=env_kwargs(kwargs))


def env_kwargs(kwargs: dict[str, Any]) -> dict[str, Any]:
    """PourEnv's keyword arguments of an IDS entry: its rig's keys (pour.sim.rigs) as the options."""
    out = dict(kwargs)
    if "rig" in out:
        from pour.sim import rigs
        out["options"] = rigs.load(out.pop("rig"))
    return out
