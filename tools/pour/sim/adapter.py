# SPDX-License-Identifier: MIT
"""The trainer's glue onto libpoursim, built on the binding in pour.sim.poursim.

SimEnv.rollout runs one whole episode in C (poursim_rollout: float softmax-linear policy inside the
firmware's pipeline) and returns it as an Episode. SimStepper advances the world tick by tick for the
Gymnasium environment through libpoursim's stepper (the same tick driver, pipeline and meter), so a stepped
episode equals the C rollout's. Failures come out as
EnvError, which the trainer reports; pour.libpoursim finds the library.
"""
from __future__ import annotations

import math
from contextlib import contextmanager
from typing import Any, Iterator

import numpy as np

from pour.policy import linear
from pour.sim import episode, poursim


@contextmanager
def _env_errors(what: str) -> Iterator[None]:
    """Re-raises pour.sim.poursim's SimError as the trainer's EnvError, prefixed with what was being done."""
    try:
        yield
    except poursim.SimError as exc:
        raise episode.EnvError(f"{what}: {exc}") from exc


def _open_world(options: dict[str, Any]) -> tuple[poursim.World, poursim.Reward]:
    """A world with the simulator's defaults and options set over them, and the reward: options k_target,
    k_spill and gamma are the trainer's (libpoursim's defaults where absent), not the world's."""
    with _env_errors("cannot load the simulator library"):
        poursim.load_library()
    opts = dict(options)
    try:
        reward = poursim.reward_from(opts)
        cfg = poursim.make_config(opts)
    except poursim.SimError as exc:
        what = f"option {exc.key} = {options[exc.key]!r}" if exc.key in options else "config"
        raise episode.EnvError(f"simulator {what}: {exc}") from exc
    with _env_errors("poursim_create"):
        return poursim.World(cfg), reward


class SimEnv:
    """rollout(w, seed, greedy) -> episode.Episode, one whole episode in C."""

    def __init__(self, n_actions: int, decision_period_ms: int, episode_s: float,
                 options: dict[str, Any] | None = None):
        opts = dict(options or {})
        opts.setdefault("episode_s", episode_s)
        # Reward shaping of training alone (the world's reward stays K_target·V_target − K_spill·V_spill).
        self.k_reversal = float(opts.pop("k_reversal", 0.0))
        if not (math.isfinite(self.k_reversal) and self.k_reversal >= 0.0):
            raise episode.EnvError(f"option k_reversal = {self.k_reversal!r}: want a finite value >= 0")
        self.world, self.reward = _open_world(opts)
        cfg = self.world.config
        if abs(cfg.dt - 1e-3) > 1e-12:
            raise episode.EnvError(f"simulator dt = {cfg.dt}: the policy's decision period assumes 1 ms ticks")
        self.tau_max_nm = float(cfg.tau_max)
        self.n_actions, self.period = n_actions, decision_period_ms
        self.levels = linear.action_levels(n_actions)

    def rollout(self, w: np.ndarray, seed: int, greedy: bool) -> episode.Episode:
        w = np.asarray(w, dtype=np.float64)
        if w.shape != (poursim.N_FEATURES, self.n_actions):
            raise episode.EnvError(f"W has shape {w.shape}, expected ({poursim.N_FEATURES}, {self.n_actions})")
        pol = poursim.Policy(w, self.levels, self.period, episode.THETA_MIN_RAD, episode.THETA_MAX_RAD,
                             episode.OMEGA_MAX_RAD_S, bool(greedy), self.k_reversal, self.reward)
        with _env_errors(f"poursim_rollout (seed {seed})"):
            ro = self.world.rollout(pol, seed)
        metrics = {"v_target": ro.poured, "v_spill": ro.spilled, "v_rotating": ro.remaining,
                   "finish_s": ro.finish_time, "return": ro.ret, "reward_sum": ro.reward_sum,
                   "max_theta": ro.max_theta, "liquid_l": ro.metrics["liquid_l"],
                   "peak_omega": ro.metrics["peak_omega"], "peak_alpha": ro.metrics["peak_alpha"],
                   "reversals": ro.metrics["reversals"], "faults": ro.metrics["faults"],
                   "fault_step": ro.metrics["fault_step"]}
        return episode.Episode(ro.features, ro.actions.astype(np.int64), ro.rewards, metrics, int(seed))


class SimStepper:
    """Tick-by-tick access for the Gymnasium environment: libpoursim's stepper (poursim.Stepper), the tick
    driver and episode meter of poursim_rollout and host_sim, inside the firmware's own pipeline on the
    firmware config for the episode's drawn rig, the agent's level as the request of each due decision. So a
    stepped episode equals the C rollout's tick for tick; nothing of the tick or the meter is in Python. The
    core's fault bits are in .faults; .torques holds the core's command of every tick so far (Q15)."""

    def __init__(self, options: dict[str, Any] | None = None, decision_period_ms: int = 1):
        self.world, self.reward = _open_world(dict(options or {}))
        self.tau_max_nm = float(self.world.config.tau_max)
        self.period = int(decision_period_ms)
        with _env_errors("poursim_stepper_create"):
            self.stepper = poursim.Stepper(self.world, self.reward, self.period)

    def reset(self, seed: int) -> None:
        with _env_errors("poursim_stepper_reset"):
            self.stepper.reset(seed)
        self.torques: list[int] = []
        self.obs = self.stepper.obs()

    @property
    def faults(self) -> int:
        return self.stepper.faults

    @property
    def v_tgt(self) -> float:
        return float(self.obs.v_target)

    @property
    def v_spill(self) -> float:
        return float(self.obs.v_spill)

    def features(self) -> np.ndarray:
        _, theta, omega, v_rot, v_tgt, v_spill = self.stepper.state()
        return episode.normalise(theta * 1e-6, omega * 1e-6, v_rot / 32768.0, v_tgt / 32768.0, v_spill / 32768.0)

    def advance(self, level: float, ticks: int, action: int = 0) -> float:
        """ticks steps with level (a fraction of tau_max) as the request of each decision due meanwhile."""
        with _env_errors("poursim_stepper_advance"):
            r, commands = self.stepper.advance(action, level, ticks)
        self.torques.extend(int(c) for c in commands)
        self.obs = self.stepper.obs()
        return r

    def metrics(self) -> dict[str, float]:
        """The episode so far as the C rollout reports it (libpoursim's meter): volumes, finish time (the
        first tick by which 99 % of what left the bucket had settled, -1 when less than 1 % left), torque
        reversals and the return."""
        m = self.stepper.episode()
        return {"v_target": float(m["poured"]), "v_spill": float(m["spilled"]), "v_rotating": float(m["remaining"]),
                "finish_s": float(m["finish_time"]), "reversals": int(m["reversals"]), "return": float(m["ret"])}
