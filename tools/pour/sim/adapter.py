# SPDX-License-Identifier: MIT
"""The trainer's glue onto libpoursim, built on the binding in pour.sim.poursim.

SimEnv.rollout runs one whole episode in C (poursim_rollout: float softmax-linear policy, the
firmware's safety envelope on every torque) and returns it as an Episode. SimStepper advances the world
tick by tick for the Gymnasium environment through the same C code: the firmware's estimator and envelope
(pour.policy.core, from the same library), so a stepped episode equals the C rollout's. Failures come out as
EnvError, which the trainer reports; pour.libpoursim finds the library.
"""
from __future__ import annotations

import math
from contextlib import contextmanager
from typing import Any, Iterator

import numpy as np

from pour.policy import core, linear
from pour.policy import fixedpoint as fp
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
                   "reversals": ro.metrics["reversals"]}
        return episode.Episode(ro.features, ro.actions.astype(np.int64), ro.rewards, metrics, int(seed))


class SimStepper:
    """Tick-by-tick access for the Gymnasium env, as the firmware sees the rig: the sensor sample through the
    firmware's estimator (firmware/src/sensors.c), torques through its safety envelope with the motion limits
    (firmware/src/safety.c), both called in C through pour.policy.core with the defaults poursim_rollout uses."""

    def __init__(self, options: dict[str, Any] | None = None):
        self.world, self.reward = _open_world(dict(options or {}))
        self.tau_max_nm = float(self.world.config.tau_max)
        with _env_errors("the firmware core in libpoursim"):
            fw = core.control_config()
        self.safety_config = fw.safety
        self.sensors_config = fw.sensors
        self.sensors_config.encoder_bits = int(self.world.config.encoder_bits)

    def reset(self, seed: int) -> None:
        with _env_errors("poursim_reset"):
            self.obs = self.world.reset(seed)
        self.safety = core.Envelope(self.safety_config)
        self.estimator = core.Estimator(self.sensors_config)
        self.seq = 0
        self.state = (0, 0, 0, 0, 0, 0)
        self._sense()

    def _sense(self) -> None:
        o = self.obs
        s = self.estimator.update(self.seq, o.encoder, o.scale_rotating_g, o.scale_target_g)
        if s is not None:  # a sample the firmware would refuse leaves the last state in place
            self.state = s
        self.seq += 1

    @property
    def v_tgt(self) -> float:
        return float(self.obs.v_target)

    @property
    def v_spill(self) -> float:
        return float(self.obs.v_spill)

    def features(self) -> np.ndarray:
        _, theta, omega, v_rot, v_tgt, v_spill = self.state
        return episode.normalise(theta * 1e-6, omega * 1e-6, v_rot / 32768.0, v_tgt / 32768.0, v_spill / 32768.0)

    def advance(self, level: float, ticks: int) -> float:
        req = fp.float_to_q15(level)
        r = 0.0
        with _env_errors("poursim_step"):
            for _ in range(ticks):
                cmd = self.safety.apply(req, self.state[1], self.state[2])
                self.obs = self.world.step(cmd / 32768.0)
                self._sense()
                r += self.reward.step(self.obs.v_target, self.obs.v_spill)
        return r
