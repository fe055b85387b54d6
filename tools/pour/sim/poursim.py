# SPDX-License-Identifier: MIT
"""Python binding of libpoursim (host_sim/include/poursim/poursim.h) through ctypes.

The library is looked for at $POUR_SIM_LIB, then $POUR_BUILD_DIR/lib/libpoursim.so, then
<source>/build/host/lib/libpoursim.so, then <source>/build/*/lib/libpoursim.so (pour.paths). Build it with
`cmake --build --preset host`.

    from pour.sim import poursim
    world = poursim.World(poursim.default_config(), seed=1)
    obs = world.step(0.3)                      # torque 0.3·tau_max for 1 ms
    pol = poursim.Policy(w=np.zeros((6, 11)), levels=np.linspace(-1, 1, 11), decision_period=10)
    ro = world.rollout(pol, seed=7)            # a whole episode in C: ro.features, ro.actions, ro.rewards

Process-safe and thread-safe across worlds (each World owns its own Box2D world). Episodes in parallel:
the trainer's executors (pour.train.executors: a process pool, or Ray), one world per worker.
"""
from __future__ import annotations

import ctypes as C
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from pour import functions, libpoursim, records
from pour.libpoursim import SimError  # the binding's error, raised by the loader too

N_FEATURES = 6
MAX_ACTIONS = 16
ERR_LEN = 256
REGIONS = ("rotating", "target", "spilled", "flight")


_DP = C.POINTER(C.c_double)


# The plain records that cross the C API on purpose, by their C names; their ctypes classes are built from
# libpoursim's own layout table (pour.records), none is written here. The config is a handle, not a record.
RECORDS = {"ObsStruct": "poursim_obs_t", "RewardStruct": "poursim_reward_t", "PolicyStruct": "poursim_policy_t",
           "BuffersStruct": "poursim_rollout_buffers_t", "EpisodeStruct": "poursim_episode_t",
           "RetentionStruct": "poursim_retention_t", "SloshStruct": "poursim_slosh_t",
           "DriveCheckStruct": "poursim_drive_check_t", "SensorCheckStruct": "poursim_sensor_check_t"}
RETENTION_MAX = 181  # POURSIM_RETENTION_MAX (the table gives the arrays' length; this is for callers)


def _r(name: str) -> type:
    """The ctypes class of a record, by its Python name here (ObsStruct) or its C name."""
    return records.record(RECORDS.get(name, name))


def __getattr__(name: str) -> type:
    if name in RECORDS:
        return _r(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def library_candidates() -> list[Path]:
    """Where load_library() looks, in order ($POUR_SIM_LIB alone when it is set)."""
    return libpoursim.candidates()


def load_library() -> functions.Functions:
    """libpoursim's functions, declared from the library's own function table (pour.functions); SimError
    says where it looked if it is not there."""
    return functions.library()


def _err() -> C.Array:
    return C.create_string_buffer(ERR_LEN)


@dataclass(frozen=True)
class KeyInfo:
    """One config key as host_sim/include/poursim/config_fields.h declares it."""
    integer: bool
    min: float
    max: float
    default: float
    unit: str
    doc: str


_keys: dict[str, KeyInfo] | None = None


def describe() -> dict[str, KeyInfo]:
    """Every config key in the library's order, with its declaration (poursim_config_key_info)."""
    global _keys
    if _keys is None:
        lib, keys = load_library(), {}
        while (name := lib.poursim_config_key(len(keys))) is not None:
            integer, lo, hi, default = C.c_int(), C.c_double(), C.c_double(), C.c_double()
            unit, doc = C.c_char_p(), C.c_char_p()
            if lib.poursim_config_key_info(name, C.byref(integer), C.byref(lo), C.byref(hi), C.byref(default),
                                           C.byref(unit), C.byref(doc)) != 0:
                raise SimError(f"libpoursim lists config key {name!r} but does not describe it")
            keys[name.decode()] = KeyInfo(bool(integer.value), lo.value, hi.value, default.value,
                                          unit.value.decode(), doc.value.decode())
        _keys = keys
    return _keys


def config_keys() -> tuple[str, ...]:
    """The names of every config key, in the library's order."""
    return tuple(describe())


def _read(ptr: int, key: str) -> float | int:
    v, e = C.c_double(), _err()
    if load_library().poursim_config_get(ptr, key.encode(), C.byref(v), e, ERR_LEN) != 0:
        raise SimError(e.value.decode(errors="replace"), key)
    return int(v.value) if describe()[key].integer else v.value


def _read_all(ptr: int) -> dict[str, float | int]:
    return {k: _read(ptr, k) for k in describe()}


class Config:
    """A simulator config held by libpoursim (poursim_config_new): read by key or attribute, set by key.

    Python keeps no copy of the C struct: the keys, their types and ranges come from the library."""

    def __init__(self, src: int | None = None):
        self._lib = load_library()
        self._ptr = self._lib.poursim_config_new(src)
        if not self._ptr:
            raise SimError("poursim_config_new: out of memory")

    @property
    def handle(self) -> int:
        """The poursim_config_t * to pass to the C API."""
        return self._ptr

    def __del__(self) -> None:
        if getattr(self, "_ptr", None):
            self._lib.poursim_config_free(self._ptr)
            self._ptr = None

    def __getitem__(self, key: str) -> float | int:
        return _read(self._ptr, key)

    def __getattr__(self, key: str) -> float | int:
        if key.startswith("_") or key not in describe():
            raise AttributeError(key)
        return _read(self._ptr, key)

    def __setitem__(self, key: str, value: float | str) -> None:
        if key not in describe():
            raise SimError(f"unknown config key '{key}'", key)
        if isinstance(value, str):
            text = value
        elif isinstance(value, (int, np.integer)):
            text = str(int(value))
        else:
            text = format(float(value), ".17g")
        e = _err()
        if self._lib.poursim_config_set(self._ptr, key.encode(), text.encode(), e, ERR_LEN) != 0:
            raise SimError(e.value.decode(errors="replace"), key)

    def keys(self) -> tuple[str, ...]:
        return config_keys()

    def as_dict(self) -> dict[str, float | int]:
        return _read_all(self._ptr)

    def validate(self) -> None:
        e = _err()
        if self._lib.poursim_config_validate(self._ptr, e, ERR_LEN) != 0:
            raise SimError(e.value.decode(errors="replace"))

    def write(self, path: str | os.PathLike) -> None:
        """A loadable config file of every key (poursim_config_write: temp file, then renamed)."""
        e = _err()
        if self._lib.poursim_config_write(self._ptr, str(path).encode(), e, ERR_LEN) != 0:
            raise SimError(e.value.decode(errors="replace"))


def default_config() -> dict[str, float | int]:
    """The simulator's defaults (config_fields.h), as a dict of config keys."""
    return Config().as_dict()


def make_config(overrides: Mapping[str, float | str] | None = None,
                path: str | os.PathLike | None = None) -> Config:
    """Defaults, then a config file (if any), then overrides (numbers, or text passed as is); validated.

    SimError names a bad key, and carries it in .key when an override was refused.
    """
    cfg = Config()
    e = _err()
    if path is not None and cfg._lib.poursim_config_load(str(path).encode(), cfg.handle, e, ERR_LEN) != 0:
        raise SimError(e.value.decode())
    for key, value in (overrides or {}).items():
        cfg[key] = value
    cfg.validate()
    return cfg


def _as_config(config: Config | Mapping[str, float] | None) -> Config:
    return config if isinstance(config, Config) else make_config(config)


@dataclass
class Obs:
    step: int
    t: float
    theta: float
    omega: float
    v_rotating: float
    v_target: float
    v_spill: float
    v_flight: float
    torque: float              # commanded in this step [N·m]
    done: bool
    motor_torque: float = 0.0  # delivered by the drive in this step [N·m]
    encoder: int = 0           # output-shaft absolute encoder count
    scale_rotating_g: int = 0  # load cell carrying the rotating bucket [g]
    scale_target_g: int = 0    # load cell under the target [g]
    drive_faults: int = 0      # the full drive's latched faults (POUR_DRIVE_FAULT_*), drive = 1
    drive_trusted: bool = True  # the drive still follows a torque

    @staticmethod
    def from_struct(o: C.Structure) -> "Obs":
        return Obs(o.step, o.t, o.theta, o.omega, o.v_rotating, o.v_target, o.v_spill, o.v_flight,
                   o.torque, bool(o.done), o.motor_torque,
                   int(o.encoder), int(o.scale_rotating_g), int(o.scale_target_g), int(o.drive_faults),
                   bool(o.drive_trusted))


@dataclass(frozen=True)
class Reward:
    """The trainer's reward, r = k_target·V_target − k_spill·V_spill per step, return Σ gamma^t r_t
    (poursim_reward_t); not part of the world."""
    k_target: float
    k_spill: float
    gamma: float

    def step(self, v_target: float, v_spill: float) -> float:
        """The reward of one step's shares, as the C rollout computes it."""
        return self.k_target * v_target - self.k_spill * v_spill


def default_reward() -> Reward:
    """libpoursim's reward (poursim_default_reward), the one host_sim reports."""
    r = load_library().poursim_default_reward()
    return Reward(r.k_target, r.k_spill, r.gamma)


def reward_from(options: dict) -> Reward:
    """Pops k_target, k_spill and gamma from options (the rest are the world's), libpoursim's default for
    each one absent; SimError names a value out of range."""
    d = default_reward()
    r = Reward(*(float(options.pop(k, getattr(d, k))) for k in ("k_target", "k_spill", "gamma")))
    e = _err()
    if load_library().poursim_reward_validate(C.byref(_r("RewardStruct")(r.k_target, r.k_spill, r.gamma)), e, ERR_LEN):
        raise SimError(e.value.decode(errors="replace"), e.value.decode(errors="replace").split()[1])
    return r


@dataclass
class Policy:
    """Float softmax-linear policy: logits = x·w, x = [θn, ωn, V_rot, V_tgt, V_spill, 1]."""
    w: np.ndarray                      # [6, n_actions]
    levels: np.ndarray                 # [n_actions], torque fractions in [-1, 1]
    decision_period: int = 10          # steps (ms) between decisions
    theta_min: float = 0.0             # [rad]
    theta_max: float = 2.356194        # [rad]
    omega_max: float = 4.0             # [rad/s]
    greedy: bool = False               # argmax instead of sampling
    k_reversal: float = 0.0            # training's reward shaping: cost of each torque reversal
    reward: Reward | None = None       # None: libpoursim's default_reward()

    def _struct(self) -> tuple[C.Structure, tuple[np.ndarray, np.ndarray]]:
        w = np.ascontiguousarray(self.w, dtype=np.float64)
        lv = np.ascontiguousarray(self.levels, dtype=np.float64)
        if w.ndim != 2 or w.shape[0] != N_FEATURES or not 2 <= w.shape[1] <= MAX_ACTIONS:
            raise SimError(f"policy w has shape {w.shape}, expected (6, 2..16)")
        if lv.shape != (w.shape[1],):
            raise SimError(f"policy levels has shape {lv.shape}, expected ({w.shape[1]},)")
        r = self.reward if self.reward is not None else default_reward()
        s = _r("PolicyStruct")(w.shape[1], int(self.decision_period), w.ctypes.data_as(_DP), lv.ctypes.data_as(_DP),
                         self.theta_min, self.theta_max, self.omega_max, 1 if self.greedy else 0,
                         _r("RewardStruct")(r.k_target, r.k_spill, r.gamma), float(self.k_reversal))
        return s, (w, lv)  # the arrays must outlive the call


@dataclass
class Rollout:
    """One episode: per decision the features, action, probabilities and summed reward."""
    seed: int
    features: np.ndarray      # [D, 6]
    actions: np.ndarray       # [D] int32
    rewards: np.ndarray       # [D] reward summed over the decision's steps
    probs: np.ndarray         # [D, n_actions]
    step_rewards: np.ndarray  # [T] (empty unless asked for)
    step_theta: np.ndarray    # [T] (empty unless asked for)
    step_torque: np.ndarray   # [T] the core's command, fraction of tau_max (empty unless asked for)
    poured: float
    spilled: float
    remaining: float
    finish_time: float        # [s], -1 if nothing was poured
    ret: float                # Σ γ^t r_t
    reward_sum: float
    max_theta: float
    metrics: dict = field(default_factory=dict)


def _n_steps(cfg: Config) -> int:
    """Room for the episode's steps: the world ends it at the first step with t >= episode_s - dt/2, so at most
    ceil(episode_s/dt) of them (the rollout reports how many it ran)."""
    return int(math.ceil(cfg.episode_s / cfg.dt))


class _Buffers:
    def __init__(self, n_decisions: int, n_actions: int, n_steps: int):
        self.features = np.zeros((n_decisions, N_FEATURES))
        self.actions = np.zeros(n_decisions, dtype=np.int32)
        self.rewards = np.zeros(n_decisions)
        self.probs = np.zeros((n_decisions, n_actions))
        self.step_rewards = np.zeros(n_steps)
        self.step_theta = np.zeros(n_steps)
        self.step_torque = np.zeros(n_steps)
        self.struct = _r("BuffersStruct")(
            n_decisions, self.features.ctypes.data_as(_DP), self.actions.ctypes.data_as(C.POINTER(C.c_int32)),
            self.rewards.ctypes.data_as(_DP), self.probs.ctypes.data_as(_DP), n_steps,
            self.step_rewards.ctypes.data_as(_DP) if n_steps else None,
            self.step_theta.ctypes.data_as(_DP) if n_steps else None,
            self.step_torque.ctypes.data_as(_DP) if n_steps else None)

    def result(self, seed: int, e: C.Structure) -> Rollout:
        d = e.n_decisions
        m = {"poured": e.poured, "spilled": e.spilled, "remaining": e.remaining, "finish_time": e.finish_time,
             "return": e.ret, "reward_sum": e.reward_sum, "max_theta": e.max_theta, "liquid_l": e.liquid_l,
             "peak_omega": e.peak_omega, "peak_alpha": e.peak_alpha, "reversals": e.reversals,
             "faults": e.faults, "fault_step": e.fault_step}
        return Rollout(seed, self.features[:d], self.actions[:d], self.rewards[:d], self.probs[:d],
                       self.step_rewards[:e.n_steps], self.step_theta[:e.n_steps], self.step_torque[:e.n_steps],
                       e.poured, e.spilled, e.remaining, e.finish_time, e.ret, e.reward_sum, e.max_theta, m)


class World:
    """One simulated scene. Not shared between threads; make one per thread or process."""

    def __init__(self, config: Config | Mapping[str, float] | None = None, seed: int | None = None):
        self._lib = load_library()
        self.config = _as_config(config)
        e = _err()
        self._w = self._lib.poursim_create(self.config.handle, e, ERR_LEN)
        if not self._w:
            raise SimError(e.value.decode())
        if seed is not None:
            self.reset(seed)

    def close(self) -> None:
        if getattr(self, "_w", None):
            self._lib.poursim_destroy(self._w)
            self._w = None

    def __del__(self) -> None:
        self.close()

    def __enter__(self) -> "World":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _check(self) -> C.c_void_p:
        if not self._w:
            raise SimError("world is closed")
        return self._w

    def reset(self, seed: int) -> Obs:
        if self._lib.poursim_reset(self._check(), int(seed) & 0xFFFFFFFF) != 0:
            raise SimError("reset failed")
        return self.observe()

    def step(self, action: float) -> Obs:
        o = _r("ObsStruct")()
        if self._lib.poursim_step(self._check(), float(action), C.byref(o)) != 0:
            if self._lib.poursim_world_error(self._check()):
                raise SimError(self._lib.poursim_world_error(self._check()).decode(errors="replace"))
            raise SimError(f"step refused action {action!r} (must be a finite number)")
        return Obs.from_struct(o)

    def set_brake(self, engaged: bool) -> None:
        """The holding brake on the bucket's axis for the steps that follow (poursim_set_brake)."""
        if self._lib.poursim_set_brake(self._check(), 1 if engaged else 0) != 0:
            raise SimError("set_brake refused (no world)")

    def observe(self) -> Obs:
        o = _r("ObsStruct")()
        self._lib.poursim_observe(self._check(), C.byref(o))
        return Obs.from_struct(o)

    def episode_config(self) -> dict[str, float | int]:
        """This episode's config: the world's with the reset seed's rand_* draws applied."""
        return _read_all(self._lib.poursim_episode_config(self._check()))

    def episode_rig(self) -> Config:
        """This episode's config as a Config (a copy): the rig a controller configured from its file knows."""
        return Config(self._lib.poursim_episode_config(self._check()))

    @property
    def n_particles(self) -> int:
        return self._lib.poursim_particle_count(self._check())

    def particles(self) -> tuple[np.ndarray, np.ndarray]:
        """Circle centres [n, 2] and radii [n] in metres."""
        n = self.n_particles
        xy = np.zeros((n, 2), dtype=np.float32)
        r = np.zeros(n, dtype=np.float32)
        self._lib.poursim_particles(self._check(), xy.ctypes.data_as(C.POINTER(C.c_float)),
                                    r.ctypes.data_as(C.POINTER(C.c_float)), n)
        return xy, r

    def regions(self) -> np.ndarray:
        """Per circle: 0 rotating, 1 target, 2 spilled, 3 in flight."""
        n = self.n_particles
        reg = np.zeros(n, dtype=np.uint8)
        self._lib.poursim_particle_regions(self._check(), reg.ctypes.data_as(C.POINTER(C.c_uint8)), n)
        return reg

    def max_overlap(self) -> float:
        return self._lib.poursim_max_overlap(self._check())

    def max_wall_penetration(self) -> float:
        return self._lib.poursim_max_wall_penetration(self._check())

    def trajectory_hash(self) -> int:
        return int(self._lib.poursim_trajectory_hash(self._check()))

    def rollout(self, policy: Policy, seed: int, record_steps: bool = False) -> Rollout:
        """A whole episode in C (reset with seed first)."""
        ps, keep = policy._struct()
        n_steps = _n_steps(self.config)
        bufs = _Buffers(-(-n_steps // policy.decision_period), ps.n_actions, n_steps if record_steps else 0)
        e = _r("EpisodeStruct")()
        rc = self._lib.poursim_rollout(self._check(), C.byref(ps), int(seed) & 0xFFFFFFFF, C.byref(bufs.struct),
                                       C.byref(e))
        if rc != 0:
            raise SimError(f"rollout failed (status {rc}): check the policy's shape, levels, ranges, reward and "
                           "k_reversal")
        del keep
        return bufs.result(seed, e)


class Stepper:
    """An episode of world tick by tick with decisions from outside (poursim_stepper_*): libpoursim's own
    tick driver and episode meter, those of rollout() and host_sim, inside the firmware's pipeline (a fresh
    core per reset, for the episode's drawn rig). Keeps the world open while it lives."""

    def __init__(self, world: "World", reward: Reward, decision_period: int):
        self._lib, self.world = load_library(), world
        e = _err()
        rs = _r("RewardStruct")(reward.k_target, reward.k_spill, reward.gamma)
        self._s = self._lib.poursim_stepper_create(world._check(), C.byref(rs), int(decision_period), e, ERR_LEN)
        if not self._s:
            raise SimError(e.value.decode(errors="replace"))
        self._obs, self._state, self._ep = _r("ObsStruct")(), records.record("pour_state_t")(), _r("EpisodeStruct")()

    def __del__(self) -> None:
        if getattr(self, "_s", None):
            self._lib.poursim_stepper_destroy(self._s)
            self._s = None

    def reset(self, seed: int) -> None:
        e = _err()
        if self._lib.poursim_stepper_reset(self._s, int(seed) & 0xFFFFFFFF, e, ERR_LEN) != 0:
            raise SimError(e.value.decode(errors="replace"))

    def advance(self, action: int, level: float, ticks: int) -> tuple[float, np.ndarray]:
        """ticks steps; the rewards summed and the core's command of each step (Q15, int16)."""
        r, cmds, e = C.c_double(), np.zeros(max(int(ticks), 0), dtype=np.int16), _err()
        if self._lib.poursim_stepper_advance(self._s, int(action), float(level), int(ticks), C.byref(r),
                                             cmds.ctypes.data_as(C.POINTER(C.c_int16)), e, ERR_LEN) != 0:
            raise SimError(e.value.decode(errors="replace"))
        return r.value, cmds

    def obs(self) -> Obs:
        self._lib.poursim_stepper_obs(self._s, C.byref(self._obs))
        return Obs.from_struct(self._obs)

    def state(self) -> tuple[int, int, int, int, int, int]:
        """The core's estimated state (seq, θ [µrad], θ̇ [µrad/s], V_rot, V_tgt, V_spill Q15)."""
        s = self._state
        self._lib.poursim_stepper_state(self._s, C.byref(s))
        return (int(s.seq), int(s.theta_urad), int(s.omega_urad_s), int(s.v_rotating), int(s.v_target),
                int(s.v_spill))

    @property
    def faults(self) -> int:
        return int(self._lib.poursim_stepper_faults(self._s))

    def episode(self) -> dict:
        """The meter's figures so far, as rollout() reports them in Rollout.metrics."""
        self._lib.poursim_stepper_episode(self._s, C.byref(self._ep))
        return _struct_dict(self._ep)


@dataclass
class Retention:
    """What the bucket keeps as it tilts (poursim_measure_retention), against an ideal liquid."""
    theta: np.ndarray   # [rad], one per degree
    kept: np.ndarray    # V_rotating, mean over the seeds
    ideal: np.ndarray   # a level liquid's share below the lower lip
    onset: float        # [rad], first <= 99.5 %
    ideal_onset: float  # [rad]
    rms_gap: float


def retention(config: Config | Mapping[str, float] | None = None, seed: int = 1, n_seeds: int = 3,
              rate: float = 0.02, theta_end: float = np.radians(125)) -> Retention:
    """Servo-tilts the bucket at rate [rad/s] to theta_end [rad] once per seed; docs/simulator.md."""
    lib = load_library()
    cfg = _as_config(config)
    r, e = _r("RetentionStruct")(), _err()
    if lib.poursim_measure_retention(cfg.handle, int(seed), int(n_seeds), float(rate), float(theta_end),
                                     C.byref(r), e, ERR_LEN) != 0:
        raise SimError(e.value.decode(errors="replace"))
    n = r.n
    return Retention(np.array(r.theta[:n]), np.array(r.kept[:n]), np.array(r.ideal[:n]), r.onset, r.ideal_onset,
                     r.rms_gap)


@dataclass
class Slosh:
    """The liquid's centre of mass across the bucket after a tilt (poursim_measure_slosh)."""
    freq: float          # [Hz]
    freq_theory: float   # [Hz], first mode of a rectangular tank
    damping: float
    amplitude: float     # [m]
    noise: float         # [m]
    trace: np.ndarray    # [m], one sample a step, the oscillation about its equilibrium


def slosh(config: Config | Mapping[str, float] | None = None, seed: int = 1, n_seeds: int = 16,
          tilt: float = np.radians(12), ramp_s: float = 0.3, hold_s: float = 4.0) -> Slosh:
    """Tilts to tilt [rad] in ramp_s, holds hold_s, averages n_seeds; docs/simulator.md."""
    lib = load_library()
    cfg = _as_config(config)
    cap = int(round(hold_s / cfg.dt)) + 1
    trace, out, e = (C.c_double * cap)(), _r("SloshStruct")(), _err()
    if lib.poursim_measure_slosh(cfg.handle, int(seed), int(n_seeds), float(tilt), float(ramp_s), float(hold_s),
                                 trace, cap, C.byref(out), e, ERR_LEN) != 0:
        raise SimError(e.value.decode(errors="replace"))
    return Slosh(out.freq, out.freq_theory, out.damping, out.amplitude, out.noise, np.array(trace[:out.n]))


def _struct_dict(st: C.Structure) -> dict:
    return {name: (list(getattr(st, name)) if isinstance(getattr(st, name), C.Array) else getattr(st, name))
            for name, _ in st._fields_}


def measure_drive(config: Config | Mapping[str, float] | None = None) -> dict:
    """The drive on the empty bucket against Newton and its datasheet line (poursim_measure_drive)."""
    lib = load_library()
    cfg = _as_config(config)
    out, e = _r("DriveCheckStruct")(), _err()
    if lib.poursim_measure_drive(cfg.handle, C.byref(out), e, ERR_LEN) != 0:
        raise SimError(e.value.decode(errors="replace"))
    return _struct_dict(out)


def measure_sensors(config: Config | Mapping[str, float] | None = None, seed: int = 1) -> dict:
    """Encoder and load cells against mass, momentum and their config (poursim_measure_sensors)."""
    lib = load_library()
    cfg = _as_config(config)
    out, e = _r("SensorCheckStruct")(), _err()
    if lib.poursim_measure_sensors(cfg.handle, int(seed), C.byref(out), e, ERR_LEN) != 0:
        raise SimError(e.value.decode(errors="replace"))
    return _struct_dict(out)


def features(theta_min: float, theta_max: float, omega_max: float, theta: float, omega: float, v_rotating: float,
             v_target: float, v_spill: float) -> np.ndarray:
    """poursim_features: the C rollout's normalisation of one state, [6] with the bias."""
    p = _r("PolicyStruct")(theta_min=theta_min, theta_max=theta_max, omega_max=omega_max)
    x = (C.c_double * N_FEATURES)()
    load_library().poursim_features(C.byref(p), theta, omega, v_rotating, v_target, v_spill, x)
    return np.array(x[:])


def version() -> str:
    return load_library().poursim_version().decode()


def uniform_levels(n_actions: int) -> np.ndarray:
    """Torque levels evenly spaced in [-1, 1], as weights.h specifies."""
    return np.linspace(-1.0, 1.0, n_actions)


__all__: Sequence[str] = ("SimError", "World", "Policy", "Reward", "default_reward", "reward_from", "features", "Rollout", "Obs", "Retention", "Slosh", "default_config",
                          "make_config", "retention", "slosh", "measure_drive", "measure_sensors",
                          "load_library", "uniform_levels", "Stepper", "Config", "KeyInfo", "describe", "config_keys", "REGIONS", "version")
