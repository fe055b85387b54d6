# SPDX-License-Identifier: MIT
"""pour's Gymnasium ids, declared once: pour.sim.gym_env registers them when it is imported, and so does the
installed package's start-up hook (_pour_gymnasium) as soon as a program imports gymnasium. Registration
is lazy: the entry point is a string, so gymnasium imports pour.sim.gym_env (and opens libpoursim) only
when an id is made."""
from __future__ import annotations

from typing import Any

ENTRY_POINT = "pour.sim.gym_env:PourEnv"

# The rig's spread that training randomises over (configs/train/pour11.toml's [env.options]), for
# pour/PourRandomised-v0.
RANDOMISED_RIG = {"rand_fill": 0.2, "rand_target_dx": 0.02, "rand_pivot_height": 0.02, "rand_motor": 0.15,
                  "rand_bucket_mass": 0.2, "rand_liquid": 0.2, "rand_sensor": 0.5}

# id -> PourEnv keyword arguments. max_episode_steps (MAX_EPISODE_STEPS): decisions in the default 10 s
# episode at the default 10 ms period.
IDS: dict[str, dict[str, Any]] = {
    "pour/Pour-v0": {},
    "pour/PourRandomised-v0": {"options": RANDOMISED_RIG},
    "pour/PourToy-v0": {"backend": "toy"},
}
MAX_EPISODE_STEPS = 1000


def register_all() -> None:
    """Registers every id that gymnasium's registry does not hold yet (so a second call changes nothing)."""
    import gymnasium as gym

    for env_id, kwargs in IDS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=ENTRY_POINT, max_episode_steps=MAX_EPISODE_STEPS,
                         kwargs=dict(kwargs))
