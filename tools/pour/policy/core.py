# SPDX-License-Identifier: MIT
"""The firmware core itself (firmware/src/*.c, linked into libpoursim), driven from Python through ctypes.

Python keeps its own bit-exact copy of the fixed-point kernels only (pour.policy.fixedpoint: quantisation,
logits, softmax, argmax); the stateful parts — the safety envelope, the sensor estimator and the 1 kHz
control step — are the C code, called here, never a Python mirror of it:

    from pour.policy import core
    env = core.Envelope()                          # pour_safety_t, default config
    cmd = env.apply(32767, theta_urad=0, omega_urad_s=0); env.active   # POUR_LIMIT_* bits
    est = core.Estimator(encoder_bits=17)          # pour_estimator_t
    state = est.update(seq, encoder, scale_rotating_g, scale_target_g)  # None: a sample it refuses
    ctl = core.Controller(weights_h.parse_weights_h(path), supervisor_checks=0)  # pour_control_t
    out = ctl.step(sample=(seq, encoder, m_rot, m_tgt), estop=False)

The structures mirror firmware/include/pour/*.h field for field; tests/python/test_core_properties.py
compiles a C program that checks every size and offset against them.
"""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from pour import libpoursim

q15 = C.c_int16
POLICY_MAX_ACTIONS = 16
LIMIT_CLAMP, LIMIT_SLEW, LIMIT_ANGLE_MAX, LIMIT_ANGLE_MIN, LIMIT_SPEED, LIMIT_ACCEL = 0x01, 0x02, 0x04, 0x08, 0x10, 0x20
MODE_IDLE, MODE_RUN, MODE_FAULT, MODE_ESTOP = 0, 1, 2, 3
FAULT_STALE_INPUT, FAULT_ESTOP, FAULT_BAD_INPUT, FAULT_LINK = 0x0001, 0x0002, 0x0004, 0x0100
SPEED_BAND_MAX_URAD_S = 100000000  # POUR_SAFETY_OMEGA_MAX_URAD_S


class CoreError(RuntimeError):
    """The core refused a config (its pour_status_t name in the message)."""


class _Struct(C.Structure):
    def __repr__(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(f"{k}={getattr(self, k)!r}" for k, _ in self._fields_) + ")"


class SafetyConfig(_Struct):
    _fields_ = [("tau_limit", q15), ("slew_per_tick", q15), ("theta_min_urad", C.c_int32),
                ("theta_max_urad", C.c_int32), ("omega_max_urad_s", C.c_int32), ("alpha_max_urad_s2", C.c_int32),
                ("omega_slack_urad_s", C.c_int32), ("torque_per_rad_s", q15)]


class SafetyState(_Struct):
    _fields_ = [("config", SafetyConfig), ("torque", q15), ("active", C.c_uint8), ("alpha_step_urad_s", C.c_int32),
                ("gain_q32", C.c_int32), ("ceiling_urad_s", C.c_int32), ("floor_urad_s", C.c_int32)]


class SensorsConfig(_Struct):
    _fields_ = [("encoder_bits", C.c_uint8), ("bandwidth_rad_s", C.c_uint16), ("scale_min_g", C.c_int32),
                ("scale_max_g", C.c_int32), ("mass_min_g", C.c_int32), ("jump_max_urad", C.c_int32)]


class EstimatorState(_Struct):
    _fields_ = [("config", SensorsConfig), ("gain_theta_q24", C.c_int32), ("gain_omega_q24", C.c_int32),
                ("started", C.c_bool), ("last_seq", C.c_uint32), ("theta_q16", C.c_int64), ("omega_q16", C.c_int64),
                ("m0_g", C.c_int32)]


class PlantState(_Struct):
    _fields_ = [("seq", C.c_uint32), ("theta_urad", C.c_int32), ("omega_urad_s", C.c_int32), ("v_rotating", q15),
                ("v_target", q15), ("v_spill", q15)]


class SensorSample(_Struct):
    _fields_ = [("seq", C.c_uint32), ("encoder", C.c_uint32), ("scale_rotating_g", C.c_int32),
                ("scale_target_g", C.c_int32)]


class ObsNorm(_Struct):
    _fields_ = [("theta_min_urad", C.c_int32), ("theta_max_urad", C.c_int32), ("omega_max_urad_s", C.c_int32)]


class PolicyWeights(_Struct):
    _fields_ = [("n_actions", C.c_uint8), ("w_frac_bits", C.c_uint8), ("decision_period_ms", C.c_uint16),
                ("w", C.POINTER(C.c_int16)), ("action_levels", C.POINTER(q15)), ("norm", ObsNorm),
                ("tau_max_mnm", C.c_int32), ("content_hash", C.c_uint32)]


class SupervisorConfig(_Struct):
    _fields_ = [("checks", C.c_uint8), ("theta_margin_urad", C.c_int32), ("omega_max_urad_s", C.c_int32),
                ("window_ms", C.c_uint8), ("torque_min", q15), ("omega_against_urad_s", C.c_int32),
                ("against_ms", C.c_uint8), ("encoder_move_urad", C.c_int32), ("encoder_ms", C.c_uint8),
                ("volume_step_max", q15), ("accel_full_urad_s2", C.c_int32), ("accel_passive_urad_s2", C.c_int32)]


class StopConfig(_Struct):
    _fields_ = [("torque_max", q15), ("return_speed_urad_s", C.c_int32), ("return_gain_per_s", C.c_uint16),
                ("torque_per_rad_s", q15), ("rest_theta_urad", C.c_int32), ("rest_omega_urad_s", C.c_int32),
                ("timeout_ms", C.c_uint16)]


class ControlConfig(_Struct):
    _fields_ = [("safety", SafetyConfig), ("sensors", SensorsConfig), ("input_timeout_ms", C.c_uint16),
                ("safe_torque", q15), ("policy_mode", C.c_int), ("seed", C.c_uint32),
                ("plausible_theta_urad", C.c_int32), ("plausible_omega_urad_s", C.c_int32),
                ("plausible_volume_sum", C.c_int32), ("supervisor", SupervisorConfig), ("stop", StopConfig)]


class ControlInput(_Struct):
    _fields_ = [("sensors_fresh", C.c_bool), ("sensors", SensorSample), ("estop", C.c_bool),
                ("clear_faults", C.c_bool), ("link_fault", C.c_bool), ("stop", C.c_bool), ("reset", C.c_bool)]


class ControlOutput(_Struct):
    _fields_ = [("torque", q15), ("action", C.c_uint8), ("probs", q15 * POLICY_MAX_ACTIONS), ("mode", C.c_uint8),
                ("faults", C.c_uint16), ("limits", C.c_uint8), ("tick", C.c_uint32), ("brake", C.c_bool),
                ("power", C.c_bool)]


# pour_control_t is opaque here: Python never reads it, only lends the core room for it (the layout test
# checks that sizeof(pour_control_t) fits).
CONTROL_STATE_BYTES = 4096
MIRRORED = {"pour_safety_config_t": SafetyConfig, "pour_safety_t": SafetyState,
            "pour_sensors_config_t": SensorsConfig, "pour_estimator_t": EstimatorState, "pour_state_t": PlantState,
            "pour_sensors_t": SensorSample, "pour_obs_norm_t": ObsNorm, "pour_policy_weights_t": PolicyWeights,
            "pour_supervisor_config_t": SupervisorConfig, "pour_stop_config_t": StopConfig,
            "pour_control_config_t": ControlConfig, "pour_control_input_t": ControlInput,
            "pour_control_output_t": ControlOutput}

_lib: C.CDLL | None = None


def load() -> C.CDLL:
    """libpoursim (pour.libpoursim opens it) with the core's entry points declared; SimError if it is missing."""
    global _lib
    if _lib is not None:
        return _lib
    lib = libpoursim.load()
    P = C.POINTER
    sig: dict[str, tuple[list[Any], Any]] = {
        "pour_status_name": ([C.c_int], C.c_char_p),
        "pour_safety_default_config": ([], SafetyConfig),
        "pour_safety_init": ([P(SafetyState), P(SafetyConfig)], C.c_int),
        "pour_safety_apply": ([P(SafetyState), q15, C.c_int32, C.c_int32], q15),
        "pour_safety_force": ([P(SafetyState), q15], None),
        "pour_sensors_default_config": ([], SensorsConfig),
        "pour_estimator_init": ([P(EstimatorState), P(SensorsConfig)], C.c_int),
        "pour_estimator_reset": ([P(EstimatorState)], None),
        "pour_estimator_update": ([P(EstimatorState), P(SensorSample), P(PlantState)], C.c_bool),
        "pour_sensors_theta_urad": ([C.c_uint32, C.c_uint8], C.c_int32),
        "pour_control_default_config": ([], ControlConfig),
        "pour_control_init": ([C.c_void_p, P(ControlConfig), P(PolicyWeights)], C.c_int),
        "pour_control_step": ([C.c_void_p, P(ControlInput), P(ControlOutput)], None),
    }
    try:
        for name, (args, res) in sig.items():
            fn = getattr(lib, name)
            fn.argtypes, fn.restype = args, res
    except AttributeError as e:
        raise libpoursim.SimError(f"libpoursim does not export the firmware core (missing symbol: {e})") from e
    _lib = lib
    return lib


def _check(status: int, what: str) -> None:
    if status != 0:
        raise CoreError(f"{what}: {load().pour_status_name(status).decode()}")


def _with(struct: C.Structure, overrides: dict[str, int]) -> C.Structure:
    names = {f for f, _ in struct._fields_}
    for k, v in overrides.items():
        if k not in names:
            raise CoreError(f"unknown field {k!r} of {type(struct).__name__}")
        setattr(struct, k, int(v))
    return struct


def safety_config(**overrides: int) -> SafetyConfig:
    """pour_safety_default_config() with the named fields replaced."""
    return _with(load().pour_safety_default_config(), overrides)


def sensors_config(**overrides: int) -> SensorsConfig:
    """pour_sensors_default_config() with the named fields replaced."""
    return _with(load().pour_sensors_default_config(), overrides)


def control_config() -> ControlConfig:
    """pour_control_default_config() (set nested fields on the result: cfg.safety.tau_limit = ...)."""
    return load().pour_control_default_config()


class Envelope:
    """pour_safety_t: apply(requested, θ, θ̇) -> the command; .active holds the POUR_LIMIT_* bits."""

    def __init__(self, config: SafetyConfig | None = None):
        self._lib = load()
        self.config = config if config is not None else self._lib.pour_safety_default_config()
        self.s = SafetyState()
        _check(self._lib.pour_safety_init(C.byref(self.s), C.byref(self.config)), "pour_safety_init")

    def apply(self, requested: int, theta_urad: int, omega_urad_s: int) -> int:
        return int(self._lib.pour_safety_apply(C.byref(self.s), int(requested), int(theta_urad), int(omega_urad_s)))

    def force(self, torque: int) -> None:
        self._lib.pour_safety_force(C.byref(self.s), int(torque))

    @property
    def active(self) -> int:
        return int(self.s.active)

    @property
    def torque(self) -> int:
        return int(self.s.torque)


class Estimator:
    """pour_estimator_t: update(seq, encoder, scale_rotating_g, scale_target_g) -> (seq, θ, θ̇, V_rot, V_tgt,
    V_spill), or None for a sample the firmware refuses (nothing changes then)."""

    def __init__(self, config: SensorsConfig | None = None, **overrides: int):
        self._lib = load()
        self.config = config if config is not None else sensors_config(**overrides)
        self.s = EstimatorState()
        self._state = PlantState()
        _check(self._lib.pour_estimator_init(C.byref(self.s), C.byref(self.config)), "pour_estimator_init")

    def reset(self) -> None:
        self._lib.pour_estimator_reset(C.byref(self.s))

    def update(self, seq: int, encoder: int, scale_rotating_g: int, scale_target_g: int) -> tuple | None:
        smp = SensorSample(int(seq) & 0xFFFFFFFF, int(encoder) & 0xFFFFFFFF, int(scale_rotating_g), int(scale_target_g))
        if not self._lib.pour_estimator_update(C.byref(self.s), C.byref(smp), C.byref(self._state)):
            return None
        s = self._state
        return (int(s.seq), int(s.theta_urad), int(s.omega_urad_s), int(s.v_rotating), int(s.v_target), int(s.v_spill))


def theta_urad(count: int, bits: int) -> int:
    """pour_sensors_theta_urad: θ [µrad] of a raw encoder count."""
    return int(load().pour_sensors_theta_urad(int(count) & 0xFFFFFFFF, int(bits)))


@dataclass
class Output:
    torque: int
    action: int
    probs: list[int]
    mode: int
    faults: int
    limits: int
    tick: int
    brake: bool
    power: bool


class Controller:
    """pour_control_t on a parsed weights.h (pour.policy.weights_h.WeightsH): step() is one 1 ms tick of
    pour_control_step()."""

    def __init__(self, weights: Any, config: ControlConfig | None = None):
        self._lib = load()
        self.config = config if config is not None else control_config()
        self._w = np.ascontiguousarray(weights.w_q, dtype=np.int16)
        self._levels = np.ascontiguousarray(weights.levels_q15, dtype=np.int16)
        n = weights.norm
        self.weights = PolicyWeights(int(weights.n_actions), int(weights.w_frac_bits), int(weights.decision_period_ms),
                                     self._w.ctypes.data_as(C.POINTER(C.c_int16)),
                                     self._levels.ctypes.data_as(C.POINTER(q15)),
                                     ObsNorm(n.theta_min_urad, n.theta_max_urad, n.omega_max_urad_s),
                                     int(weights.tau_max_mnm), int(weights.content_hash))
        self._ctl = (C.c_uint64 * (CONTROL_STATE_BYTES // 8))()
        self._in, self._out = ControlInput(), ControlOutput()
        _check(self._lib.pour_control_init(self._ctl, C.byref(self.config), C.byref(self.weights)),
               "pour_control_init")

    def step(self, sample: Sequence[int] | None = None, estop: bool = False, clear_faults: bool = False,
             link_fault: bool = False, stop: bool = False, reset: bool = False) -> Output:
        """sample (seq, encoder, scale_rotating_g, scale_target_g), or None for no fresh sample this tick."""
        i = self._in
        i.sensors_fresh = sample is not None
        smp = sample if sample is not None else (0, 0, 0, 0)
        i.sensors = SensorSample(int(smp[0]) & 0xFFFFFFFF, int(smp[1]) & 0xFFFFFFFF, int(smp[2]), int(smp[3]))
        i.estop, i.clear_faults, i.link_fault, i.stop, i.reset = estop, clear_faults, link_fault, stop, reset
        self._lib.pour_control_step(self._ctl, C.byref(i), C.byref(self._out))
        o = self._out
        return Output(int(o.torque), int(o.action), list(o.probs), int(o.mode), int(o.faults), int(o.limits),
                      int(o.tick), bool(o.brake), bool(o.power))
