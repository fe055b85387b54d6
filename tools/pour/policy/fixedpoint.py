# SPDX-License-Identifier: MIT
"""Bit-exact Python reference of the firmware core's fixed-point kernels (firmware/src/obs.c, policy.c).

Quantisation of the state, the policy's logits, the softmax, argmax and the seeded sampling: an independent
implementation, written from docs/fixed-point.md, that the golden vectors (tools/pour/policy/golden.py) pin the C
code against bit for bit. The stateful parts of the core (safety envelope, estimator, control step) have no
Python copy: pour.core calls the C code, and tests/python/test_core_properties.py checks it against
docs/safety.md. Integers are Python ints (no overflow); where C saturates, so does this code. Rounding is
"half up" (floor(x + 1/2)) everywhere, as the C code's (x + half) >> shift and (2 n + d) // (2 d) give it.
"""
from __future__ import annotations

import math

from dataclasses import dataclass
from typing import Sequence

import numpy as np

Q15_ONE = 32768
Q15_MAX = 32767
Q15_MIN = -32768
INT32_MAX = 2**31 - 1
INT32_MIN = -(2**31)
N_OBS = 5
N_FEATURES = 6
MIN_ACTIONS = 2
MAX_ACTIONS = 16
LOG2E_Q16 = 94548  # round(log2(e) * 2^16)
DEFAULT_SEED = 2463534242  # replaces seed 0 (xorshift32 must never hold 0)

# 2^(-j/64) in Q24, j = 0..64: the C table exp2_neg_q24 (a test checks the C source holds these values).
EXP2_TABLE_Q24 = [int(np.floor(2.0 ** (-j / 64.0) * 2**24 + 0.5)) for j in range(65)]


@dataclass(frozen=True)
class ObsNorm:
    """Observation normalisation: θ in [theta_min, theta_max] µrad and θ̇ in ±omega_max µrad/s map to [0, 1]."""

    theta_min_urad: int
    theta_max_urad: int
    omega_max_urad_s: int

    def rad(self) -> tuple[float, float, float]:
        """theta_min, theta_max [rad] and omega_max [rad/s], as the float policy takes them."""
        return self.theta_min_urad * 1e-6, self.theta_max_urad * 1e-6, self.omega_max_urad_s * 1e-6

    def validate(self) -> None:
        if self.theta_max_urad <= self.theta_min_urad:
            raise ValueError(f"norm: theta_max_urad ({self.theta_max_urad}) must exceed theta_min_urad "
                             f"({self.theta_min_urad})")
        if self.omega_max_urad_s <= 0:
            raise ValueError(f"norm: omega_max_urad_s ({self.omega_max_urad_s}) must be > 0")
        for name in ("theta_min_urad", "theta_max_urad", "omega_max_urad_s"):
            v = getattr(self, name)
            if not INT32_MIN <= v <= INT32_MAX:
                raise ValueError(f"norm: {name} ({v}) is outside int32")


def sat(x: int, lo: int, hi: int) -> int:
    return lo if x < lo else hi if x > hi else x


def sat_q15(x: int) -> int:
    return sat(int(x), Q15_MIN, Q15_MAX)


def sat_i32(x: int) -> int:
    return sat(int(x), INT32_MIN, INT32_MAX)


def round_half_up_shift(x: int, shift: int) -> int:
    """round(x / 2^shift), ties up: (x + 2^(shift-1)) >> shift, with Python's floor >>."""
    return (x + (1 << (shift - 1))) >> shift if shift > 0 else x


def float_to_q15(x: float) -> int:
    """A fraction as Q15, the host's one rule (libpoursim's poursim_fraction_to_q15 is the C side): round half
    up, then saturate (+1.0 -> 32767, -1.0 -> -32768, +-inf to the limits); NaN -> 0, never a plausible value."""
    x = float(x)
    if math.isnan(x):
        return 0
    return sat_q15(math.floor(max(-65536.0, min(65536.0, x * Q15_ONE + 0.5))))


def ratio_q15(num: int, den: int) -> int:
    """round(32768 num / den) saturated to [0, 32767], den > 0 (obs.c ratio_q15)."""
    if num <= 0:
        return 0
    if num >= den:
        return Q15_MAX
    return min((num * 2 * Q15_ONE + den) // (2 * den), Q15_MAX)


def quantize_obs(norm: ObsNorm, theta_urad: int, omega_urad_s: int, v_rotating: int, v_target: int,
                 v_spill: int) -> list[int]:
    """pour_obs_quantize: the five Q15 observations in [0, 32767]. Volumes are Q15 already."""
    span = norm.theta_max_urad - norm.theta_min_urad
    return [
        ratio_q15(theta_urad - norm.theta_min_urad, span),
        ratio_q15(omega_urad_s + norm.omega_max_urad_s, 2 * norm.omega_max_urad_s),
        max(int(v_rotating), 0),
        max(int(v_target), 0),
        max(int(v_spill), 0),
    ]


def logits_q15(w_q: np.ndarray, frac_bits: int, obs_q15: Sequence[int]) -> list[int]:
    """pour_policy_logits: Q16.15 int32 logits of x = [obs, 1.0] times W (int16, frac_bits fraction bits)."""
    w = np.asarray(w_q, dtype=np.int64)
    if w.ndim != 2 or w.shape[0] != N_FEATURES:
        raise ValueError(f"W must have shape ({N_FEATURES}, n_actions), got {w.shape}")
    x = [int(v) for v in obs_q15] + [Q15_ONE]
    out = []
    for a in range(w.shape[1]):
        acc = sum(x[k] * int(w[k, a]) for k in range(N_FEATURES))
        out.append(sat_i32(round_half_up_shift(acc, frac_bits)))
    return out


EXP_D_CUTOFF = 386124  # smallest d whose y = (d * LOG2E_Q16 + 32768) >> 16 has y >> 15 > 16


def exp_neg_q16(d: int) -> int:
    """exp(-d / 32768) in Q16 for 0 <= d < 2^32 (policy.c exp_neg_q16)."""
    if d >= EXP_D_CUTOFF:
        return 0
    y = (d * LOG2E_Q16 + 32768) >> 16  # the C code's d + ((d * 7253 + 8192) >> 14), the same value
    k = y >> 15
    r = y & 0x7FFF
    j, frac = r >> 9, r & 0x1FF
    step = EXP2_TABLE_Q24[j] - EXP2_TABLE_Q24[j + 1]
    v = EXP2_TABLE_Q24[j] - ((step * frac + 256) >> 9)
    shift = 8 + k
    return (v + (1 << (shift - 1))) >> shift


def softmax_q15(logits: Sequence[int]) -> list[int]:
    """pour_policy_softmax_q15: Q15 probabilities of Q16.15 logits."""
    m = max(logits)
    e = [exp_neg_q16(m - int(v)) for v in logits]
    s = sum(e)
    return [min((ei * 32768 + s // 2) // s, Q15_MAX) for ei in e]


def argmax(logits: Sequence[int]) -> int:
    """Index of the largest logit, ties to the lowest index."""
    best = 0
    for a in range(1, len(logits)):
        if logits[a] > logits[best]:
            best = a
    return best


def xorshift32(state: int) -> int:
    """One xorshift32 (13, 17, 5) step: returns the new state (also the drawn value)."""
    x = state & 0xFFFFFFFF
    x ^= (x << 13) & 0xFFFFFFFF
    x ^= x >> 17
    x ^= (x << 5) & 0xFFFFFFFF
    return x


def sample(probs: Sequence[int], rng: int) -> tuple[int, int]:
    """pour_policy_sample: (action, new rng state)."""
    rng = xorshift32(rng)
    total = sum(int(p) for p in probs)
    u = (rng * total) >> 32
    cum = 0
    for a, p in enumerate(probs):
        cum += int(p)
        if u < cum:
            return a, rng
    return len(probs) - 1, rng


@dataclass
class PolicyEval:
    logits: list[int]
    probs: list[int]
    action: int


class FixedPolicy:
    """pour_policy_t: greedy or sampled (seeded xorshift32) evaluation of a quantised policy."""

    def __init__(self, w_q: np.ndarray, frac_bits: int, sampled: bool = False, seed: int = 0):
        self.w_q = np.asarray(w_q, dtype=np.int64)
        self.frac_bits = int(frac_bits)
        self.sampled = sampled
        self.rng = seed if seed != 0 else DEFAULT_SEED

    def eval(self, obs_q15: Sequence[int]) -> PolicyEval:
        lg = logits_q15(self.w_q, self.frac_bits, obs_q15)
        pr = softmax_q15(lg)
        if self.sampled:
            a, self.rng = sample(pr, self.rng)
        else:
            a = argmax(lg)
        return PolicyEval(lg, pr, a)


def float_policy_probs(w_float: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The trainer's float policy: softmax([x, 1] · W), max subtracted."""
    feats = np.append(np.asarray(x, dtype=np.float64), 1.0)
    z = feats @ np.asarray(w_float, dtype=np.float64)
    z = z - z.max()
    e = np.exp(z)
    return e / e.sum()
