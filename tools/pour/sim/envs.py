# SPDX-License-Identifier: MIT
"""Episode sources for the trainer: the Box2D simulator (through tools/pour/sim/poursim.py) and a toy.

Both produce the same Episode record: per decision the six features the policy saw, the action it
took and the reward summed over the decision period, plus end-of-episode metrics. The toy is a
one-dimensional tilt model with a crude liquid: fast to run, used by the unit tests of the trainer
(convergence, resume, reproducibility) where the simulator's library is not needed.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from pour.policy import linear
from pour.sim.poursim import Reward
from pour.sim.episode import (N_FEATURES, NORM, OMEGA_MAX_RAD_S, THETA_MAX_RAD, THETA_MIN_RAD,  # noqa: F401
                              EnvError, Episode, normalise)


def choose(w: np.ndarray, x: np.ndarray, greedy: bool, rng: np.random.Generator) -> int:
    """Greedy: argmax of the logits, ties to the lowest index. Sampled: inverse CDF of softmax."""
    logits = x @ w
    if greedy:
        return int(np.argmax(logits))
    p = linear.softmax(logits)
    u = rng.random()
    return int(min(np.searchsorted(np.cumsum(p), u, side="right"), p.size - 1))


class ToyEnv:
    """A 1-D tilt plant with a liquid that pours past an angle that grows as the bucket empties.

    Spill grows with the outflow rate and with the tilt speed, so the best policy tilts fast to the
    pouring angle, then follows it at a controlled rate -- the same shape of problem as the real one.
    """

    DEFAULTS = {"k_target": 1.0, "k_spill": 5.0, "tau_max": 4.0, "inertia": 0.25, "damping": 0.3,
                "gravity": 1.5, "flow": 2.0, "flow_safe": 0.6, "omega_safe": 1.5}

    def __init__(self, n_actions: int, decision_period_ms: int, episode_s: float,
                 options: dict[str, Any] | None = None):
        opts = dict(self.DEFAULTS)
        for k, v in (options or {}).items():
            if k not in self.DEFAULTS:
                raise EnvError(f"toy env: unknown option {k!r}; known: {', '.join(sorted(self.DEFAULTS))}")
            opts[k] = float(v)
        self.o = opts
        self.reward = Reward(opts["k_target"], opts["k_spill"], 1.0)  # the trainer discounts
        self.tau_max_nm = opts["tau_max"]
        self.levels = linear.action_levels(n_actions)
        self.period = decision_period_ms
        self.steps = int(round(episode_s * 1000))

    def reset(self, seed: int) -> np.random.Generator:
        """Starts an episode: full bucket, upright, at rest; the seed varies the pouring angle."""
        rng = np.random.default_rng(seed)
        self.theta, self.omega = 0.0, 0.0
        self.v_rot, self.v_tgt, self.v_spill = 1.0, 0.0, 0.0
        self.pour_at = 0.55 + 0.05 * rng.standard_normal()  # the full bucket's first-pour angle [rad]
        self._moved: list[float] = []  # V_target + V_spill after every advance
        return rng

    def features(self) -> np.ndarray:
        return normalise(self.theta, self.omega, self.v_rot, self.v_tgt, self.v_spill)

    def advance(self, level: float, ticks: int) -> float:
        """ticks 1 ms steps at torque level x tau_max; returns the reward summed over them."""
        o = self.o
        tau = level * o["tau_max"]
        theta, omega, v_rot, v_tgt, v_spill = self.theta, self.omega, self.v_rot, self.v_tgt, self.v_spill
        dt, r_sum = 1e-3, 0.0
        for _ in range(ticks):
            inertia = o["inertia"] * (0.4 + 0.6 * v_rot)
            alpha = (tau - o["gravity"] * v_rot * math.sin(theta) - o["damping"] * omega) / inertia
            omega += alpha * dt
            theta += omega * dt
            if theta >= THETA_MAX_RAD:
                theta, omega = THETA_MAX_RAD, min(omega, 0.0)
            elif theta <= 0.0:
                theta, omega = 0.0, max(omega, 0.0)
            onset = self.pour_at + 1.2 * (1.0 - v_rot)
            q = o["flow"] * max(0.0, theta - onset) * (0.3 + v_rot)
            dv = min(v_rot, q * dt)
            if dv > 0.0:
                spill = min(1.0, max(0.0, (q - o["flow_safe"]) / o["flow_safe"])
                            + max(0.0, (abs(omega) - o["omega_safe"]) / o["omega_safe"]))
                v_rot -= dv
                v_spill += dv * spill
                v_tgt += dv * (1.0 - spill)
            r_sum += self.reward.step(v_tgt, v_spill)
        self.theta, self.omega, self.v_rot, self.v_tgt, self.v_spill = theta, omega, v_rot, v_tgt, v_spill
        self._moved.append(v_tgt + v_spill)
        return r_sum

    def metrics(self) -> dict[str, float]:
        """The episode so far: volumes, and the finish time (the first decision by whose start 99 % of what
        left the bucket had landed; -1 when less than 1 % left)."""
        moved, final = np.asarray(self._moved[:-1]), self.v_tgt + self.v_spill
        done = np.flatnonzero(moved >= 0.99 * final) if final >= 0.01 else np.array([], dtype=int)
        return {"v_target": self.v_tgt, "v_spill": self.v_spill, "v_rotating": self.v_rot,
                "finish_s": float((done[0] + 1) * self.period * 1e-3) if done.size else -1.0}

    def rollout(self, w: np.ndarray, seed: int, greedy: bool) -> Episode:
        rng = self.reset(seed)
        n_dec = self.steps // self.period
        xs = np.empty((n_dec, N_FEATURES))
        acts = np.empty(n_dec, dtype=np.int64)
        rews = np.zeros(n_dec)
        for d in range(n_dec):
            x = self.features()
            a = choose(w, x, greedy, rng)
            xs[d], acts[d] = x, a
            rews[d] = self.advance(float(self.levels[a]), self.period)
        return Episode(xs, acts, rews, self.metrics(), seed)


def make_env(kind: str, n_actions: int, decision_period_ms: int, episode_s: float,
             options: dict[str, Any] | None = None):
    """An object with rollout(w, seed, greedy) -> Episode."""
    if kind == "toy":
        return ToyEnv(n_actions, decision_period_ms, episode_s, options)
    if kind == "sim":
        from pour.sim import adapter  # numpy and ctypes only until a world is made
        return adapter.SimEnv(n_actions, decision_period_ms, episode_s, options)
    raise EnvError(f"unknown env kind {kind!r}: expected 'sim' or 'toy'")


def make_stepper(kind: str, n_actions: int, decision_period_ms: int, episode_s: float,
                 options: dict[str, Any] | None = None):
    """An object with reset(seed), features(), advance(level, ticks) -> reward, v_tgt, v_spill."""
    if kind == "toy":
        return ToyEnv(n_actions, decision_period_ms, episode_s, options)
    if kind == "sim":
        from pour.sim import adapter
        return adapter.SimStepper(options, decision_period_ms)
    raise EnvError(f"unknown env kind {kind!r}: expected 'sim' or 'toy'")
