# SPDX-License-Identifier: MIT
"""A Gymnasium environment over the pour simulator, for users who bring their own RL library.

    import gymnasium                                # the installed package registers pour's ids
    env = gymnasium.make("pour/Pour-v0")            # Box2D simulator (libpoursim), 11 torque levels
    env = gymnasium.make("pour.sim.gym_env:pour/Pour-v0", render_mode="rgb_array")  # Gymnasium's own way
    env = gymnasium.make("pour/PourRandomised-v0")  # the rig randomised as training randomises it
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

One env step is one decision period (10 ms by default) at the torque level of the action, exactly as
training rollouts and the firmware hold an action between decisions: the level is a request into the
firmware's own pipeline (estimator, supervisor, envelope, controlled stop), as in the rollouts; info["faults"]
holds the core's latched fault bits (0 while it runs). Observation: the five normalised
state variables [θn, ωn, V_rotating, V_target, V_spill] in [0, 1] (float32). Reward: the per-tick
reward K_target·V_target − K_spill·V_spill summed over the decision period. The 10 s episode ends by
time limit (truncated=True), or earlier when the core faults (terminated=True: the core has stopped the
bucket and holds it; info["fault_names"] names the faults). The last step's info["is_success"] says whether
the episode met the results table's targets (pour.sim.episode: poured >= 95 %, spilled <= 3 %, finished
within 8 s) without a fault. Only the 'sim' backend renders (rgb_array); the toy plant has no scene.
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from pour import functions
from pour.policy import linear
from pour.sim import envs, episode, gym_ids


class PourEnv(gym.Env):
    """Pouring with a discrete torque action; backend 'sim' (Box2D) or 'toy' (the trainer's toy plant).

    reset(seed=s) runs the plant of seed s, exactly as host_sim --seed s does; reset() without a seed goes on
    with seeds drawn from the env's seeded generator. reset(options={"rig": {KEY: VALUE}}) sets simulator
    config keys over the env's own options from that episode on (the same keys as host_sim --set). A reset
    refused (an unknown option or key, a value out of range, a bad seed) changes nothing: the env goes on
    as it was."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 100}

    def __init__(self, backend: str = "sim", n_actions: int = 11, decision_period_ms: int = 10,
                 episode_s: float = 10.0, options: dict[str, Any] | None = None, render_mode: str | None = None):
        if backend not in ("sim", "toy"):
            raise envs.EnvError(f"backend {backend!r}: expected 'sim' or 'toy'")
        if not 2 <= int(n_actions) <= 16:
            raise envs.EnvError(f"n_actions = {n_actions}: expected 2..16")
        if int(decision_period_ms) < 1 or round(episode_s * 1000) % int(decision_period_ms):
            raise envs.EnvError(f"episode_s = {episode_s} is not a whole number of {decision_period_ms} ms periods")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise envs.EnvError(f"render_mode {render_mode!r}: expected one of {self.metadata['render_modes']}")
        if render_mode is not None and backend != "sim":
            raise envs.EnvError("render_mode: only the 'sim' backend has a scene to draw")
        self._backend, self._n_actions, self._episode_s = backend, int(n_actions), float(episode_s)
        self._options = dict(options or {})
        self._plant = envs.make_stepper(backend, int(n_actions), int(decision_period_ms), float(episode_s),
                                        self._options)
        self.render_mode = render_mode
        self.metadata = dict(self.metadata, render_fps=1000 // int(decision_period_ms))
        if backend != "sim":
            self.metadata["render_modes"] = []  # the toy plant has no scene to draw
        self.levels = linear.action_levels(int(n_actions))
        self.period = int(decision_period_ms)
        self.max_decisions = int(round(episode_s * 1000)) // self.period
        self.action_space = spaces.Discrete(int(n_actions))
        self.observation_space = spaces.Box(0.0, 1.0, shape=(5,), dtype=np.float32)
        self._k = 0
        self._started = False

    @property
    def tau_max_nm(self) -> float:
        """The plant's full-scale torque [N.m] (the actions' levels are fractions of it)."""
        return float(self._plant.tau_max_nm)

    def _obs(self) -> np.ndarray:
        return np.asarray(self._plant.features()[:5], dtype=np.float32)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        # Everything is checked before anything changes: a refused reset leaves the env as it was.
        unknown = set(options or {}) - {"rig"}
        if unknown:
            raise envs.EnvError(f"reset options {sorted(unknown)}: the only option is 'rig' (simulator config keys)")
        rig = (options or {}).get("rig")
        if rig is not None and not isinstance(rig, dict):
            raise envs.EnvError(f"reset option rig = {rig!r}: expected a dict of simulator config keys")
        if seed is not None and not (isinstance(seed, (int, np.integer)) and 0 <= int(seed) < 2**32):
            raise envs.EnvError(f"seed {seed!r}: expected an integer 0 .. 2^32 - 1 (host_sim's --seed)")
        if rig:
            merged = {**self._options, **rig}
            plant = envs.make_stepper(self._backend, self._n_actions, self.period, self._episode_s, merged)
            self._options, self._plant = merged, plant
        super().reset(seed=seed)
        # A given seed is the plant's seed, as host_sim's --seed; without one the next seed comes from the
        # env's generator (seeded by the last reset with a seed), so a sequence of resets is reproducible.
        plant_seed = int(seed) if seed is not None else int(self.np_random.integers(0, 2**32 - 1))
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
        faults = int(getattr(self._plant, "faults", 0))
        terminated = faults != 0  # the core stopped the bucket: nothing the agent does changes it now
        truncated = not terminated and self._k >= self.max_decisions
        info = {"v_target": float(self._plant.v_tgt), "v_spill": float(self._plant.v_spill),
                "t_s": self._k * self.period * 1e-3, "faults": faults}
        if terminated:
            info["fault_names"] = functions.fault_names(faults)
        if terminated or truncated:
            self._started = False
            info["is_success"] = self._success(faults)
        return self._obs(), reward, terminated, truncated, info

    def _success(self, faults: int) -> bool:
        """The episode met the results table's targets (pour.sim.episode) without a fault."""
        if faults:
            return False
        finish = float(self._plant.metrics()["finish_s"])
        return (100.0 * float(self._plant.v_tgt) >= episode.POURED_MIN_PCT
                and 100.0 * float(self._plant.v_spill) <= episode.SPILLED_MAX_PCT
                and 0.0 <= finish <= episode.FINISH_MAX_S)


    def render(self) -> np.ndarray | None:
        """rgb_array: the scene now (uint8 [H, W, 3]), drawn from the world; None without a render_mode."""
        if self.render_mode != "rgb_array":
            return None
        return scene_rgb(self._plant.world)


def greedy_metrics(env: PourEnv, act: Callable[[np.ndarray], int], seed: int) -> dict[str, float]:
    """One whole episode of env from reset(seed=seed), act(observation) -> action at every decision, for a
    policy that poursim_rollout cannot run (one that is not softmax-linear): the plant's end-of-episode
    metrics (the 'sim' backend's are the C rollout's: volumes, finish_s, reversals, return; the toy counts
    no reversals and has no discounted return: NaN) and reward_sum, the episode's rewards summed."""
    obs, _ = env.reset(seed=seed)
    truncated, reward_sum = False, 0.0
    while not truncated:
        obs, reward, _, truncated, _ = env.step(act(obs))
        reward_sum += reward
    return {"reversals": np.nan, "return": np.nan, **env.unwrapped._plant.metrics(), "reward_sum": reward_sum}


def mlp_actor(layers: Sequence[np.ndarray]) -> Callable[[np.ndarray], int]:
    """The greedy action of an MLP actor (Stable-Baselines3's MlpPolicy: tanh hidden layers, then a linear
    layer to the action logits) from its layers [W1, b1, ..., Wk, bk] (W [inputs][outputs]): argmax of the
    logits, ties to the lowest index, in float64."""
    pairs = [(np.asarray(layers[i], dtype=np.float64), np.asarray(layers[i + 1], dtype=np.float64))
             for i in range(0, len(layers), 2)]
    if len(layers) % 2 or not pairs:
        raise envs.EnvError(f"an MLP actor needs weight and bias pairs, got {len(layers)} arrays")

    def act(obs: np.ndarray) -> int:
        h = np.asarray(obs, dtype=np.float64)
        for w, b in pairs[:-1]:
            h = np.tanh(h @ w + b)
        return int(np.argmax(h @ pairs[-1][0] + pairs[-1][1]))
    return act


# Liquid colours by where a circle is (poursim_particle_regions): bucket, target, spilled, in flight.
_REGION_RGB = np.array([[245, 224, 178], [245, 224, 178], [200, 40, 40], [60, 110, 220]], dtype=np.uint8)


def scene_rgb(world: Any, width: int = 320, height: int = 240) -> np.ndarray:
    """A picture of the world: the ground, both buckets (grey) and the circles coloured by region."""
    c = world.config
    obs = world.observe()
    wi, wall, hh = c.bucket_inner_width / 2, c.bucket_wall, c.bucket_height / 2
    x0, x1, y0 = -0.30, c.target_dx + 0.30, -0.02
    scale = min(width / (x1 - x0), height / (c.pivot_height + 0.30 - y0))
    img = np.full((height, width, 3), 255, dtype=np.uint8)
    ys, xs = np.mgrid[0:height, 0:width]
    px, py = x0 + (xs + 0.5) / scale, y0 + (height - ys - 0.5) / scale  # pixel centres [m]
    img[py < 0.0] = (140, 140, 140)
    boxes = [(-wi - wall, -hh, wi + wall, -hh + wall), (-wi - wall, -hh, -wi, hh), (wi, -hh, wi + wall, hh)]
    cos, sin = np.cos(obs.theta), np.sin(obs.theta)
    # The rotating bucket in its own frame (θ tilts clockwise about the pivot), the target upright on the floor.
    lx, ly = cos * px - sin * (py - c.pivot_height), sin * px + cos * (py - c.pivot_height)
    for bx0, by0, bx1, by1 in boxes:
        img[(lx >= bx0) & (lx <= bx1) & (ly >= by0) & (ly <= by1)] = (110, 110, 110)
        tx, ty = px - c.target_dx, py - hh
        img[(tx >= bx0) & (tx <= bx1) & (ty >= by0) & (ty <= by1)] = (110, 110, 110)
    xy, radius = world.particles()
    region = world.regions()
    for (cx, cy), r, g in zip(xy, radius, region):
        i0, i1 = int((cx - r - x0) * scale), int((cx + r - x0) * scale) + 1
        j0, j1 = int(height - (cy + r - y0) * scale), int(height - (cy - r - y0) * scale) + 1
        i0, j0, i1, j1 = max(i0, 0), max(j0, 0), min(i1, width), min(j1, height)
        if i0 >= i1 or j0 >= j1:
            continue
        inside = (px[j0:j1, i0:i1] - cx) ** 2 + (py[j0:j1, i0:i1] - cy) ** 2 <= r * r
        img[j0:j1, i0:i1][inside] = _REGION_RGB[min(int(g), 3)]
    return img


gym_ids.register_all()
