# SPDX-License-Identifier: MIT
"""Bit-exact Python reference of the firmware core's fixed-point maths (firmware/src/*.c).

Every function here mirrors one C function; golden vectors (tools/pour/golden.py) and the equivalence
tests rely on the two agreeing bit for bit. Integers are Python ints (no overflow); where C saturates,
so does this code. Rounding is "half up" (floor(x + 1/2)) everywhere, as the C code's
(x + half) >> shift and (2 n + d) // (2 d) give it.
"""
from __future__ import annotations

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
    """Round to nearest (half up), then saturate: +1.0 -> 32767, -1.0 -> -32768."""
    return sat_q15(int(np.floor(float(x) * Q15_ONE + 0.5)))


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


def obs_float(norm: ObsNorm, theta_rad: float, omega_rad_s: float, v_rotating: float, v_target: float,
              v_spill: float) -> np.ndarray:
    """The trainer's float normalisation (docs/weights-h.md), features without the bias."""
    tmin, tmax = norm.theta_min_urad * 1e-6, norm.theta_max_urad * 1e-6
    wmax = norm.omega_max_urad_s * 1e-6
    return np.array([
        np.clip((theta_rad - tmin) / (tmax - tmin), 0.0, 1.0),
        np.clip((omega_rad_s + wmax) / (2.0 * wmax), 0.0, 1.0),
        np.clip(v_rotating, 0.0, 1.0),
        np.clip(v_target, 0.0, 1.0),
        np.clip(v_spill, 0.0, 1.0),
    ])


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


# Safety envelope (safety.c), for simulations that want the firmware's torque shaping in Python.
LIMIT_CLAMP, LIMIT_SLEW, LIMIT_ANGLE_MAX, LIMIT_ANGLE_MIN = 0x01, 0x02, 0x04, 0x08
LIMIT_SPEED, LIMIT_ACCEL = 0x10, 0x20
SPEED_BAND_MAX_URAD_S = 100000000  # |θ̇| the speed band works with, saturated: 100 rad/s (2x plausible)


@dataclass
class SafetyConfig:
    tau_limit: int = Q15_MAX
    slew_per_tick: int = 3277
    theta_min_urad: int = -87266
    theta_max_urad: int = 2356194
    omega_max_urad_s: int = 2000000
    alpha_max_urad_s2: int = 3400000
    torque_per_rad_s: int = 16384
    omega_slack_urad_s: int = 800000


class SafetyEnvelope:
    """pour_safety_t: angle limits, clamp, the speed band (governor), slew, then the band's and the angle's cuts
    toward zero again."""

    def __init__(self, config: SafetyConfig | None = None):
        self.config = c = config or SafetyConfig()
        self.torque = 0
        self.active = 0
        self.alpha_step = max((c.alpha_max_urad_s2 + 500) // 1000, 1)
        self.gain_q32 = (c.torque_per_rad_s * (1 << 32) + 500000) // 1000000
        self.ceiling = c.omega_slack_urad_s
        self.floor = -c.omega_slack_urad_s

    def _angle_cut(self, torque: int, theta_urad: int) -> int:
        c = self.config
        if torque > 0 and theta_urad >= c.theta_max_urad:
            self.active |= LIMIT_ANGLE_MAX
            return 0
        if torque < 0 and theta_urad <= c.theta_min_urad:
            self.active |= LIMIT_ANGLE_MIN
            return 0
        return torque

    def _band_torque(self, margin_urad_s: int) -> int:
        t = round_half_up_shift(margin_urad_s * self.gain_q32, 32)
        return sat(t, -self.config.tau_limit, self.config.tau_limit)

    def apply(self, requested: int, theta_urad: int, omega_urad_s: int) -> int:
        c = self.config
        self.active = 0
        cmd = self._angle_cut(int(requested), theta_urad)
        if cmd > c.tau_limit:
            cmd, self.active = c.tau_limit, self.active | LIMIT_CLAMP
        elif cmd < -c.tau_limit:
            cmd, self.active = -c.tau_limit, self.active | LIMIT_CLAMP
        w = sat(int(omega_urad_s), -SPEED_BAND_MAX_URAD_S, SPEED_BAND_MAX_URAD_S)
        self.ceiling = min(c.omega_max_urad_s, self.ceiling + self.alpha_step, max(w, 0) + c.omega_slack_urad_s)
        self.floor = max(-c.omega_max_urad_s, self.floor - self.alpha_step, min(w, 0) - c.omega_slack_urad_s)
        hi = self._band_torque(self.ceiling - w)
        lo = self._band_torque(self.floor - w)
        hi_bit = LIMIT_SPEED if self.ceiling == c.omega_max_urad_s else LIMIT_ACCEL
        lo_bit = LIMIT_SPEED if self.floor == -c.omega_max_urad_s else LIMIT_ACCEL
        if cmd > hi:
            cmd, self.active = hi, self.active | hi_bit
        elif cmd < lo:
            cmd, self.active = lo, self.active | lo_bit
        delta = cmd - self.torque
        if delta > c.slew_per_tick:
            cmd, self.active = self.torque + c.slew_per_tick, self.active | LIMIT_SLEW
        elif delta < -c.slew_per_tick:
            cmd, self.active = self.torque - c.slew_per_tick, self.active | LIMIT_SLEW
        if cmd > max(hi, 0):
            cmd, self.active = max(hi, 0), self.active | hi_bit
        elif cmd < min(lo, 0):
            cmd, self.active = min(lo, 0), self.active | lo_bit
        cmd = self._angle_cut(cmd, theta_urad)
        self.torque = cmd
        return cmd

    def force(self, torque: int) -> None:
        self.torque = int(torque)
        self.active = 0


# Sensor estimator (sensors.c): raw encoder count and scale readings -> the plant state.
TWO_PI_URAD_Q8 = 1608495439  # round(2π · 10^6 · 2^8): one turn [µrad] Q8
ESTIMATOR_GAP_MAX = 32  # ticks a seq gap is credited with, at most


@dataclass
class SensorsConfig:
    encoder_bits: int = 17
    bandwidth_rad_s: int = 300
    scale_min_g: int = -2000
    scale_max_g: int = 30000
    mass_min_g: int = 1000
    jump_max_urad: int = 10000


def encoder_theta_urad(count: int, bits: int) -> int:
    """θ [µrad] of a raw single-turn count: counts above 2^(bits-1) are below upright (negative); the
    magnitude rounded half up, the sign applied after (θ(-c) = -θ(c))."""
    c = count - (1 << bits) if count > (1 << (bits - 1)) else count
    mag = (abs(c) * TWO_PI_URAD_Q8 + (1 << (bits + 7))) >> (bits + 8)
    return -mag if c < 0 else mag


def mass_ratio_q15(num: int, den: int) -> int:
    """round(32768 num / den) clipped to [0, 32767], for 0 < den < 2^16."""
    if num <= 0:
        return 0
    if num >= den:
        return Q15_MAX
    return min((num * Q15_ONE + den // 2) // den, Q15_MAX)


class Estimator:
    """pour_estimator_t: θ from the encoder, θ̇ from a critically damped tracking loop, volumes from the scales."""

    def __init__(self, config: SensorsConfig | None = None):
        self.config = c = config or SensorsConfig()
        bw = c.bandwidth_rad_s
        self.gain_theta_q24 = (2 * bw * (1 << 24) + 500) // 1000
        self.gain_omega_q24 = (bw * bw * (1 << 24) + 500000) // 1000000
        self.reset()

    def reset(self) -> None:
        self.started = False
        self.last_seq = 0
        self.theta_q16 = 0
        self.omega_q16 = 0
        self.m0_g = 0

    def update(self, seq: int, encoder: int, scale_rotating_g: int, scale_target_g: int) -> tuple | None:
        """(seq, θ, θ̇, V_rot, V_tgt, V_spill), or None for an implausible sample (nothing changes)."""
        c = self.config
        if not 0 <= encoder < (1 << c.encoder_bits):
            return None
        for m in (scale_rotating_g, scale_target_g):
            if not c.scale_min_g <= m <= c.scale_max_g:
                return None
        m0 = self.m0_g if self.started else scale_rotating_g + scale_target_g
        if m0 < c.mass_min_g:
            return None
        theta = encoder_theta_urad(encoder, c.encoder_bits)
        advance = 0  # θ̂'s advance over this tick [µrad/tick] Q16; θ̇ is this, not ω̂ (which lags 2a/ωn)
        if not self.started:
            self.started, self.m0_g = True, m0
            self.theta_q16, self.omega_q16 = theta << 16, 0
        else:
            n = sat((seq - self.last_seq) & 0xFFFFFFFF, 1, ESTIMATOR_GAP_MAX)
            predicted = self.theta_q16 + (n - 1) * self.omega_q16
            e = sat_i32(theta - round_half_up_shift(predicted, 16))
            if abs(e) > c.jump_max_urad * n * n:
                return None  # a count that jumped, not a motion
            advance = self.omega_q16 + round_half_up_shift(e * self.gain_theta_q24, 8)
            self.theta_q16 = predicted + advance
            self.omega_q16 += round_half_up_shift(e * self.gain_omega_q24, 8)
        self.last_seq = seq & 0xFFFFFFFF
        omega = sat_i32(round_half_up_shift(advance * 1000, 16))
        v_rot = mass_ratio_q15(scale_rotating_g, m0)
        v_tgt = mass_ratio_q15(scale_target_g, m0)
        v_spill = sat(Q15_ONE - v_rot - v_tgt, 0, Q15_MAX)  # neither cell carries it: spilled or in flight
        return (seq, theta, omega, v_rot, v_tgt, v_spill)


# Control step (control.c): modes, faults and the decision schedule, for bit-exact replays in Python.
MODE_IDLE, MODE_RUN, MODE_FAULT, MODE_ESTOP = 0, 1, 2, 3
FAULT_STALE_INPUT, FAULT_ESTOP, FAULT_BAD_INPUT = 0x0001, 0x0002, 0x0004


@dataclass
class ControlConfig:
    safety: SafetyConfig | None = None
    sensors: SensorsConfig | None = None
    input_timeout_ms: int = 20
    safe_torque: int = 0
    sampled: bool = False
    seed: int = 1
    plausible_theta_urad: int = 3141593
    plausible_omega_urad_s: int = 50000000
    plausible_volume_sum: int = 65536


@dataclass
class ControlOutput:
    torque: int
    action: int
    probs: list[int]
    mode: int
    faults: int
    limits: int
    tick: int


class Controller:
    """pour_control_t: one call of step() is one 1 ms tick of pour_control_step().

    sample is a raw sensor sample (seq, encoder, scale_rotating_g, scale_target_g); the estimator turns it
    into the state (seq, theta_urad, omega_urad_s, v_rotating, v_target, v_spill), volumes in Q15. The
    supervisor (its seq check included) is not mirrored: the golden vectors run with its checks disarmed.
    """

    def __init__(self, w_q: np.ndarray, frac_bits: int, levels_q15: Sequence[int], decision_period_ms: int,
                 norm: ObsNorm, config: ControlConfig | None = None):
        self.config = config or ControlConfig()
        self.safety = SafetyEnvelope(self.config.safety or SafetyConfig())
        self.estimator = Estimator(self.config.sensors or SensorsConfig())
        self.policy = FixedPolicy(w_q, frac_bits, sampled=self.config.sampled, seed=self.config.seed)
        self.levels = [int(v) for v in levels_q15]
        self.period = int(decision_period_ms)
        self.norm = norm
        self.mode, self.faults, self.tick = MODE_IDLE, 0, 0
        self.ms_since_fresh, self.ms_to_decision = 0, 0
        self.state = (0, 0, 0, 0, 0, 0)
        self.action, self.probs = 0, [0] * MAX_ACTIONS

    def _plausible(self, s: Sequence[int]) -> bool:
        c = self.config
        _, theta, omega, vr, vt, vs = (int(v) for v in s)
        if abs(theta) > c.plausible_theta_urad or abs(omega) > c.plausible_omega_urad_s:
            return False
        if vr < 0 or vt < 0 or vs < 0:
            return False
        return vr + vt + vs <= c.plausible_volume_sum

    def _force_safe(self) -> int:
        sc = self.safety.config
        theta = self.state[1]
        torque = self.config.safe_torque
        if (torque > 0 and theta >= sc.theta_max_urad) or (torque < 0 and theta <= sc.theta_min_urad):
            torque = 0
        self.safety.force(torque)
        return torque

    def _out(self, torque: int) -> ControlOutput:
        return ControlOutput(torque, self.action, list(self.probs), self.mode, self.faults, self.safety.active,
                             self.tick)

    def step(self, sample: Sequence[int] | None, estop: bool = False, clear_faults: bool = False) -> ControlOutput:
        """sample None means no fresh sample this tick."""
        self.tick = (self.tick + 1) & 0xFFFFFFFF
        if estop:
            self.mode = MODE_ESTOP
            self.faults |= FAULT_ESTOP
            self.safety.force(0)
            return self._out(0)
        if self.mode == MODE_ESTOP:
            self.mode = MODE_FAULT
        if clear_faults and self.mode == MODE_FAULT:
            self.faults, self.mode, self.ms_since_fresh = 0, MODE_IDLE, 0
        fresh = False
        if sample is not None and self.mode == MODE_IDLE:
            self.estimator.reset()
        if sample is not None:
            state = self.estimator.update(*(int(v) for v in sample))
            if state is None or not self._plausible(state):
                self.faults |= FAULT_BAD_INPUT
                self.mode = MODE_FAULT
            else:
                self.state, self.ms_since_fresh, fresh = state, 0, True
        if not fresh:
            self.ms_since_fresh += 1
            if self.mode == MODE_RUN and self.ms_since_fresh > self.config.input_timeout_ms:
                self.faults |= FAULT_STALE_INPUT
                self.mode = MODE_FAULT
        if self.mode == MODE_IDLE and fresh:
            self.mode, self.ms_to_decision = MODE_RUN, 0
        if self.mode == MODE_RUN:
            if self.ms_to_decision == 0:
                e = self.policy.eval(quantize_obs(self.norm, *self.state[1:]))
                self.action = e.action
                self.probs = e.probs + [0] * (MAX_ACTIONS - len(e.probs))
                self.ms_to_decision = self.period
            self.ms_to_decision -= 1
            torque = self.safety.apply(self.levels[self.action], self.state[1], self.state[2])
        else:
            torque = self._force_safe()
        return self._out(torque)
