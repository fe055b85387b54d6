# SPDX-License-Identifier: MIT
"""What every episode source gives the trainer: the Episode record, EnvError, and the features' normalisation.

Kept apart from pour.sim.envs (which picks a source) so that a source such as pour.sim.adapter imports this and
not the module that imports it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Normalisation the policy is trained with (weights.h carries the same numbers).
THETA_MIN_RAD = 0.0
THETA_MAX_RAD = 2.356194        # 135 deg
OMEGA_MAX_RAD_S = 4.0
N_FEATURES = 6


class EnvError(RuntimeError):
    """The episode source cannot be used (library missing, bad option)."""


@dataclass
class Episode:
    """One episode, as the trainer sees it."""
    x: np.ndarray                  # [T][6] features at each decision
    actions: np.ndarray            # [T] action index
    rewards: np.ndarray            # [T] reward summed over each decision period
    metrics: dict[str, float] = field(default_factory=dict)  # v_target, v_spill, v_rotating, finish_s
    # finish_s: first time V_target + V_spill reached 99 % of its final value [s]; -1 if < 1 % moved
    seed: int = 0


def normalise(theta: float, omega: float, v_rot: float, v_tgt: float, v_spill: float) -> np.ndarray:
    """Float normalisation of the spec: clip to [0, 1]; bias feature 1.0 last."""
    def c(v: float) -> float:
        return 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)
    return np.array([c((theta - THETA_MIN_RAD) / (THETA_MAX_RAD - THETA_MIN_RAD)),
                     c((omega + OMEGA_MAX_RAD_S) / (2 * OMEGA_MAX_RAD_S)),
                     c(v_rot), c(v_tgt), c(v_spill), 1.0])
