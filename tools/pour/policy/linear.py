# SPDX-License-Identifier: MIT
"""The float softmax-linear policy pi(a|x) = softmax(x.W) and its torque levels: what the trainer learns,
the simulator's episode sources sample from, and pour.policy.fixedpoint quantises for the firmware.

x is the feature row [theta_n, omega_n, V_rot, V_tgt, V_spill, 1.0]; W is [6][n_actions].
"""
from __future__ import annotations

import numpy as np


def features(theta: float, omega: float, v_rot: float, v_tgt: float, v_spill: float, theta_min: float,
             theta_max: float, omega_max: float) -> np.ndarray:
    """The feature row of one state (docs/weights-h.md): theta [rad] over [theta_min, theta_max], omega
    [rad/s] over [-omega_max, omega_max] and the three volume shares, each clipped to [0, 1], then the bias
    1.0. The same arithmetic as libpoursim's poursim_features, which test_sim_binding compares bit for bit."""
    def c(v: float) -> float:
        return 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)
    return np.array([c((theta - theta_min) / (theta_max - theta_min)), c((omega + omega_max) / (2.0 * omega_max)),
                     c(v_rot), c(v_tgt), c(v_spill), 1.0])


def softmax(logits: np.ndarray) -> np.ndarray:
    """Row-wise softmax; the row max is subtracted before exp so large logits cannot overflow."""
    z = logits - np.max(logits, axis=-1, keepdims=True)
    e = np.exp(z)
    return e / np.sum(e, axis=-1, keepdims=True)


def probs(w: np.ndarray, x: np.ndarray) -> np.ndarray:
    """pi(.|x) for each row of x [T][F] under weights w [F][A]."""
    return softmax(x @ w)


def action_levels(n_actions: int) -> np.ndarray:
    """Torque levels evenly spaced in [-1, 1], as fractions of tau_max."""
    return np.linspace(-1.0, 1.0, n_actions)
