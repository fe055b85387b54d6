# SPDX-License-Identifier: MIT
"""What every episode source gives the trainer: the Episode record, EnvError, and the features' normalisation.

Kept apart from pour.sim.envs (which picks a source) so that a source such as pour.sim.adapter imports this and
not the module that imports it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pour.policy import linear

# Normalisation the policy is trained with (weights.h carries the same numbers).
THETA_MIN_RAD = 0.0
THETA_MAX_RAD = 2.356194        # 135 deg
OMEGA_MAX_RAD_S = 4.0
# The normalisation as a policy.json records it (pour.policy.export.write_policy).
NORM = {"theta_min_rad": THETA_MIN_RAD, "theta_max_rad": THETA_MAX_RAD, "omega_max_rad_s": OMEGA_MAX_RAD_S}
N_FEATURES = 6
# The targets an episode meets to count as a success (the results table's, pour-results; the Gymnasium env's
# info["is_success"]): poured at least this much of the liquid, spilled at most this much, finished in time.
POURED_MIN_PCT = 95.0
SPILLED_MAX_PCT = 3.0
FINISH_MAX_S = 8.0


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
    """The features of one state with the normalisation the policy is trained with, bias 1.0 last."""
    return linear.features(theta, omega, v_rot, v_tgt, v_spill, THETA_MIN_RAD, THETA_MAX_RAD, OMEGA_MAX_RAD_S)
