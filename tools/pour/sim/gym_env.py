# SPDX-License-Identifier: MIT
"""A Gymnasium environment over the pour simulator, for users who bring their own RL library.

    import gymnasium, pour.sim.gym_env
    env = gymnasium.make("pour/Pour-v0")            # Box2D simulator (libpoursim), 11 torque levels
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

One env step is one decision period (10 ms by default) at the torque level of the action, exactly as
training rollouts and the firmware hold an action between decisions: the level is a request into the
firmware's own pipeline (estimator, supervisor, envelope, controlled stop), as in the rollouts; info["faults"]
holds the core's latched fault bits (0 while it runs). Observation: the five normalised
state variables [θn, ωn, V_rotating, V_target, V_spill] in [0, 1] (float32). Reward: the per-tick
reward K_target·V_target − K_spill·V_spill summed over the decision period. The 10 s episode ends by
time limit (truncated=True); nothing terminates it earlier.
"""
from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from pour.policy import linear
from pour.sim import envs


class PourEnv(gym.Env):
    """Pouring with a discrete torque action; backend 'sim' (Box2D) or 'toy' (the trainer's toy plant)."""

    metadata = {"render_modes": []}

    def __init__(self, backend: str = "sim", n_actions: int = 11, decision_period_ms: int = 10,
                 episode_s: float = 10.0, options: dict[str, Any] | None = None):
        if backend not in ("sim", "toy"):
            raise envs.EnvError(f"backend {backend!r}: expected 'sim' or 'toy'")
        if not 2 <= int(n_actions) <= 16:
            raise envs.EnvError(f"n_actions = {n_actions}: expected 2..16")
        if int(decision_period_ms) < 1 or round(episode_s * 1000) % int(decision_period_ms):
            raise envs.EnvError(f"episode_s = {episode_s} is not a whole number of {decision_period_ms} ms periods")
        self._plant = envs.make_stepper(backend, int(n_actions), int(decision_period_ms), float(episode_s), options)
        self.levels = linear.action_levels(int(n_actions))
        self.period = int(decision_period_ms)
        self.max_decisions = int(round(episode_s * 1000)) // self.period
        self.action_space = spaces.Discrete(int(n_actions))
        self.observation_space = spaces.Box(0.0, 1.0, shape=(5,), dtype=np.float32)
        self._k = 0
        self._started = False

    def _obs(self) -> np.ndarray:
        return np.asarray(self._plant.features()[:5], dtype=np.float32)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        # The plant's own seed comes from Gymnasium's seeded generator, so reset(seed=s) is reproducible
        # and later resets without a seed continue the same sequence.
        plant_seed = int(self.np_random.integers(0, 2**32 - 1))
        self._plant.reset(plant_seed)
        self._k = 0
        self._started = True
        return self._obs(), {"plant_seed": plant_seed}

    def step(self, action):
        if not self._started:
            raise gym.error.ResetNeeded("call reset() before step()")
        if not self.action_space.contains(action):
            raise gym.error.InvalidAction(f"action {action!r} is not in {self.action_space}")
        reward = float(self._plant.advance(float(self.levels[int(action)]), self.period))
        self._k += 1
        truncated = self._k >= self.max_decisions
        if truncated:
            self._started = False
        info = {"v_target": float(self._plant.v_tgt), "v_spill": float(self._plant.v_spill),
                "t_s": self._k * self.period * 1e-3, "faults": int(getattr(self._plant, "faults", 0))}
        return self._obs(), reward, False, truncated, info


gym.register(id="pour/Pour-v0", entry_point="pour.sim.gym_env:PourEnv")
gym.register(id="pour/PourToy-v0", entry_point="pour.sim.gym_env:PourEnv", kwargs={"backend": "toy"})
