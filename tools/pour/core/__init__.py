# SPDX-License-Identifier: MIT
"""The firmware core itself (firmware/src/*.c, linked into libpoursim), driven from Python through ctypes.

Python keeps its own bit-exact copy of the fixed-point kernels only (pour.policy.fixedpoint: quantisation,
logits, softmax, argmax); the stateful parts — the safety envelope, the sensor estimator and the control
pipeline — are the C code behind handles (host_sim/include/poursim/core.h), never a Python mirror of it:

    from pour import core
    env = core.Envelope()                          # the safety envelope, default config
    cmd = env.apply(32767, theta_urad=0, omega_urad_s=0); env.active   # POUR_LIMIT_* bits
    est = core.Estimator(encoder_bits=17)          # the sensor estimator
    state = est.update(seq, encoder, scale_rotating_g, scale_target_g)  # None: a sample it refuses
    ctl = core.Controller(weights_h.parse_weights_h(path))             # the pipeline with that policy
    out = ctl.step(sample=(seq, encoder, m_rot, m_tgt), estop=False)
    ext = core.Controller(None, decision_period_ms=10)                 # decisions from outside
    if ext.update(sample): ext.request(action, torque_q15)
    out = ext.shape()

A config (core.control_config()) is an opaque block whose fields are read and set by their C names
(cfg.safety.tau_limit = 20000). Fault and mode names come from the core's own table (fault_name, mode_name).
The plain records of a tick (a sample, a state, a tick's inputs and outputs) are built from the library's
layout table (pour.records); RECORDS names them.
"""
from __future__ import annotations

import ctypes as C
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from pour import functions, records

q15 = C.c_int16
POLICY_MAX_ACTIONS = 16
LIMIT_CLAMP, LIMIT_SLEW, LIMIT_ANGLE_MAX, LIMIT_ANGLE_MIN, LIMIT_SPEED, LIMIT_ACCEL = 0x01, 0x02, 0x04, 0x08, 0x10, 0x20
SPEED_BAND_MAX_URAD_S = 100000000  # POUR_SAFETY_OMEGA_MAX_URAD_S
ERR_LEN = 256


class CoreError(RuntimeError):
    """The core refused a config (its pour_status_t name in the message)."""


# The plain records of a tick that cross the C API on purpose: Python name -> C name. Their ctypes classes
# are built from libpoursim's own layout table (pour.records); none is written here.
RECORDS = {"SensorSample": "pour_sensors_t", "PlantState": "pour_state_t", "ControlInput": "pour_control_input_t",
           "ControlOutput": "pour_control_output_t"}


def _r(name: str) -> type:
    return records.record(RECORDS[name])


def load() -> functions.Functions:
    """libpoursim's functions, the core's among them, declared from the library's own function table
    (pour.functions); SimError if it is missing."""
    return functions.library()


def _names(fn: Any, count: int) -> dict[int, str]:
    out = {}
    for i in range(count):
        name = fn(i)
        if name is not None:
            out[i] = name.decode()
    return out


fault_name, fault_names, mode_name = functions.fault_name, functions.fault_names, functions.mode_name


def __getattr__(name: str) -> Any:
    """FAULT_<NAME> and MODE_<NAME>, read from the core's name table."""
    if name in RECORDS:
        return _r(name)
    if name.startswith("FAULT_"):
        table = {n: 1 << i for i in range(16) if (n := fault_name(1 << i)) is not None}
    elif name.startswith("MODE_"):
        table = {n: m for m in range(256) if (n := mode_name(m)) is not None}
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    key = name.split("_", 1)[1]
    if key not in table:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r} (the core names {sorted(table)})")
    return table[key]


def _check_handle(h: int | None, err: C.Array, what: str) -> int:
    if not h:
        raise CoreError(f"{what}: {err.value.decode(errors='replace') or 'out of memory'}")
    return h


class Config:
    """pour_control_config_t as an opaque block; fields by their C names: cfg.input_timeout_ms,
    cfg.safety.tau_limit (the groups are the nested configs). Unknown names and values a field's type cannot
    hold raise CoreError."""

    def __init__(self, rig: Any = None):
        lib = load()
        object.__setattr__(self, "_buf", (C.c_uint8 * lib.poursim_fw_config_size())())
        lib.poursim_fw_config_init(self._buf, rig.handle if rig is not None else None)
        names = _names(lib.poursim_fw_config_field, 4096).values()
        object.__setattr__(self, "_fields", tuple(names))

    @property
    def ptr(self) -> C.Array:
        return self._buf

    def fields(self) -> tuple[str, ...]:
        return self._fields

    def get(self, name: str) -> int:
        v = C.c_int64()
        if load().poursim_fw_config_get(self._buf, name.encode(), C.byref(v)) != 0:
            raise CoreError(f"unknown field {name!r} of the core's config")
        return int(v.value)

    def set(self, name: str, value: int) -> None:
        if load().poursim_fw_config_set(self._buf, name.encode(), int(value)) != 0:
            why = "unknown field" if name not in self._fields else f"value {value!r} out of its type's range for"
            raise CoreError(f"{why} {name!r} of the core's config")

    def _group(self, name: str) -> bool:
        return any(f.startswith(name + ".") for f in self._fields)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        if self._group(name):
            return _Group(self, name)
        return self.get(name)

    def __setattr__(self, name: str, value: int) -> None:
        self.set(name, value)

    def copy(self) -> "Config":
        c = Config()
        C.memmove(c._buf, self._buf, C.sizeof(self._buf))
        return c


class _Group:
    """One nested config of a Config (cfg.safety): its fields by name. The envelope and the estimator take
    one as their config (the whole block goes to C; each reads its own group)."""

    def __init__(self, config: Config, prefix: str):
        object.__setattr__(self, "_config", config)
        object.__setattr__(self, "_prefix", prefix)

    @property
    def ptr(self) -> C.Array:
        return self._config.ptr

    def __getattr__(self, name: str) -> int:
        return self._config.get(f"{self._prefix}.{name}")

    def __setattr__(self, name: str, value: int) -> None:
        self._config.set(f"{self._prefix}.{name}", value)


def control_config(rig: Any = None, **overrides: int) -> Config:
    """pour_control_default_config(), or with rig (a poursim config) the firmware's config for that simulated
    rig (the one function the rollouts and host_sim use too), with the named top-level fields replaced."""
    c = Config(rig)
    for k, v in overrides.items():
        c.set(k, v)
    return c


def _group_config(group: str, overrides: dict[str, int]) -> _Group:
    g = _Group(Config(), group)
    for k, v in overrides.items():
        setattr(g, k, v)
    return g


def safety_config(**overrides: int) -> _Group:
    """The default config's safety.* group (the envelope's), with the named fields replaced."""
    return _group_config("safety", overrides)


def sensors_config(**overrides: int) -> _Group:
    """The default config's sensors.* group (the estimator's), with the named fields replaced."""
    return _group_config("sensors", overrides)


class _Handle:
    _destroy = ""

    def __del__(self) -> None:
        h = getattr(self, "_h", None)
        if h:
            getattr(self._lib, self._destroy)(h)
            self._h = None


class Envelope(_Handle):
    """The safety envelope on config's safety.* fields: apply(requested, θ, θ̇) -> the command; .active holds
    the POUR_LIMIT_* bits."""
    _destroy = "poursim_envelope_destroy"

    def __init__(self, config: Config | _Group | None = None):
        self._lib = load()
        self.config = config if config is not None else safety_config()
        err = C.create_string_buffer(ERR_LEN)
        self._h = _check_handle(self._lib.poursim_envelope_create(self.config.ptr, err, ERR_LEN), err, "envelope")

    def apply(self, requested: int, theta_urad: int, omega_urad_s: int) -> int:
        return int(self._lib.poursim_envelope_apply(self._h, int(requested), int(theta_urad), int(omega_urad_s)))

    def force(self, torque: int) -> None:
        self._lib.poursim_envelope_force(self._h, int(torque))

    @property
    def active(self) -> int:
        return int(self._lib.poursim_envelope_active(self._h))

    @property
    def torque(self) -> int:
        return int(self._lib.poursim_envelope_torque(self._h))

    @property
    def band(self) -> tuple[int, int]:
        """(floor, ceiling) of the speed band [µrad/s]."""
        f, c = C.c_int32(), C.c_int32()
        self._lib.poursim_envelope_band(self._h, C.byref(f), C.byref(c))
        return int(f.value), int(c.value)


def _state_tuple(s: C.Structure) -> tuple[int, int, int, int, int, int]:
    return (int(s.seq), int(s.theta_urad), int(s.omega_urad_s), int(s.v_rotating), int(s.v_target), int(s.v_spill))


class Estimator(_Handle):
    """The sensor estimator on config's sensors.* fields: update(seq, encoder, scale_rotating_g,
    scale_target_g) -> (seq, θ, θ̇, V_rot, V_tgt, V_spill), or None for a sample the firmware refuses (nothing
    changes then)."""
    _destroy = "poursim_estimator_destroy"

    def __init__(self, config: Config | _Group | None = None, **overrides: int):
        self._lib = load()
        self.config = config if config is not None else sensors_config(**overrides)
        self._state = _r("PlantState")()
        err = C.create_string_buffer(ERR_LEN)
        self._h = _check_handle(self._lib.poursim_estimator_create(self.config.ptr, err, ERR_LEN), err, "estimator")

    def reset(self) -> None:
        self._lib.poursim_estimator_reset(self._h)

    def update(self, seq: int, encoder: int, scale_rotating_g: int, scale_target_g: int) -> tuple | None:
        smp = _r("SensorSample")(int(seq) & 0xFFFFFFFF, int(encoder) & 0xFFFFFFFF, int(scale_rotating_g), int(scale_target_g))
        if not self._lib.poursim_estimator_update(self._h, C.byref(smp), C.byref(self._state)):
            return None
        return _state_tuple(self._state)


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
    refused: int
    brake: bool
    power: bool


class Controller(_Handle):
    """The firmware's control pipeline. With weights (a parsed weights.h, pour.policy.weights_h.WeightsH) its
    fixed-point policy decides and step() is one 1 ms tick of pour_control_step(); with None the decisions
    come from outside every decision_period_ms ticks of RUN: update() says when one is due, request() makes
    it, shape() gives the tick's output (the envelope, the controlled stop)."""
    _destroy = "poursim_core_destroy"

    def __init__(self, weights: Any, config: Config | None = None, decision_period_ms: int = 1):
        self._lib = load()
        self.config = config if config is not None else Config()
        err = C.create_string_buffer(ERR_LEN)
        P16 = C.POINTER(C.c_int16)
        if weights is None:
            h = self._lib.poursim_core_create(self.config.ptr, 0, 0, int(decision_period_ms), None, None, 0, 0, 0, 0,
                                              0, err, ERR_LEN)
        else:
            w = np.ascontiguousarray(weights.w_q, dtype=np.int16)
            levels = np.ascontiguousarray(weights.levels_q15, dtype=np.int16)
            n = weights.norm
            h = self._lib.poursim_core_create(self.config.ptr, int(weights.n_actions), int(weights.w_frac_bits),
                                              int(weights.decision_period_ms), w.ctypes.data_as(P16),
                                              levels.ctypes.data_as(P16), int(n.theta_min_urad),
                                              int(n.theta_max_urad), int(n.omega_max_urad_s),
                                              int(weights.tau_max_mnm), int(weights.content_hash) & 0xFFFFFFFF,
                                              err, ERR_LEN)
        self._h = _check_handle(h, err, "pour_control_init")
        self._in, self._out, self._state = _r("ControlInput")(), _r("ControlOutput")(), _r("PlantState")()

    def _input(self, sample: Sequence[int] | None, estop: bool, clear_faults: bool, link_fault: bool, stop: bool,
               reset: bool) -> C.Structure:
        i = self._in
        i.sensors_fresh = sample is not None
        smp = sample if sample is not None else (0, 0, 0, 0)
        i.sensors = _r("SensorSample")(int(smp[0]) & 0xFFFFFFFF, int(smp[1]) & 0xFFFFFFFF, int(smp[2]), int(smp[3]))
        i.estop, i.clear_faults, i.link_fault, i.stop, i.reset = estop, clear_faults, link_fault, stop, reset
        return i

    def _output(self) -> Output:
        o = self._out
        return Output(int(o.torque), int(o.action), list(o.probs), int(o.mode), int(o.faults), int(o.limits),
                      int(o.tick), int(o.refused), bool(o.brake), bool(o.power))

    def step(self, sample: Sequence[int] | None = None, estop: bool = False, clear_faults: bool = False,
             link_fault: bool = False, stop: bool = False, reset: bool = False) -> Output:
        """sample (seq, encoder, scale_rotating_g, scale_target_g), or None for no fresh sample this tick."""
        i = self._input(sample, estop, clear_faults, link_fault, stop, reset)
        self._lib.poursim_core_step(self._h, C.byref(i), C.byref(self._out))
        return self._output()

    def update(self, sample: Sequence[int] | None = None, estop: bool = False, clear_faults: bool = False,
               link_fault: bool = False, stop: bool = False, reset: bool = False) -> bool:
        """The pipeline's first stage (estimate, supervise); True when a decision is due."""
        i = self._input(sample, estop, clear_faults, link_fault, stop, reset)
        return bool(self._lib.poursim_core_update(self._h, C.byref(i)))

    def state(self) -> tuple[int, int, int, int, int, int]:
        """The estimated state (seq, θ [µrad], θ̇ [µrad/s], V_rot, V_tgt, V_spill Q15)."""
        self._lib.poursim_core_state(self._h, C.byref(self._state))
        return _state_tuple(self._state)

    def decide(self) -> None:
        """The fixed-point policy's decision (nothing without weights)."""
        self._lib.poursim_core_decide(self._h)

    def request(self, action: int, torque_q15: int) -> None:
        """A decision from outside: the action index and the torque request [Q15 of tau_max]."""
        self._lib.poursim_core_request(self._h, int(action) & 0xFF, int(torque_q15))

    def shape(self) -> Output:
        """The pipeline's last stage: the envelope (RUN), the controlled stop (FAULT), the outputs."""
        self._lib.poursim_core_shape(self._h, C.byref(self._out))
        return self._output()
