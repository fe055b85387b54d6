# SPDX-License-Identifier: MIT
"""The trainer's thin adapter onto libpoursim's C API (host_sim/include/poursim/poursim.h), by ctypes.

SimEnv.rollout runs one whole episode in C (poursim_rollout: float softmax-linear policy, the
firmware's safety envelope on every torque) and returns it as an envs.Episode. SimStepper advances
the world tick by tick for the Gymnasium environment, with the same envelope (its bit-exact Python
mirror). The library is found through POUR_SIM_LIB, then POUR_BUILD_DIR/lib, then build/*/lib.
"""
from __future__ import annotations

import ctypes as C
import glob
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from pour import envs
from pour import fixedpoint as fp
from pour import reinforce

N_FEATURES = 6
ERR_LEN = 256


class Config(C.Structure):
    _fields_ = [("dt", C.c_double), ("substeps", C.c_int), ("episode_s", C.c_double), ("settle_s", C.c_double),
                ("bucket_inner_width", C.c_double), ("bucket_height", C.c_double), ("bucket_wall", C.c_double),
                ("pivot_height", C.c_double), ("target_dx", C.c_double),
                ("bucket_mass", C.c_double), ("liquid_mass", C.c_double), ("n_particles", C.c_int),
                ("radius_min", C.c_double), ("radius_max", C.c_double),
                ("restitution_liquid", C.c_double), ("restitution_wall", C.c_double), ("friction", C.c_double),
                ("restitution_threshold", C.c_double), ("contact_hertz", C.c_double),
                ("tau_max", C.c_double), ("theta_min", C.c_double), ("theta_max", C.c_double),
                ("obs_theta_min", C.c_double), ("obs_theta_max", C.c_double), ("obs_omega_max", C.c_double),
                ("k_target", C.c_double), ("k_spill", C.c_double), ("gamma", C.c_double), ("seed", C.c_uint32)]


class Obs(C.Structure):
    _fields_ = [("step", C.c_uint32), ("t", C.c_double), ("theta", C.c_double), ("omega", C.c_double),
                ("v_rotating", C.c_double), ("v_target", C.c_double), ("v_spill", C.c_double),
                ("v_flight", C.c_double), ("obs", C.c_double * 5), ("reward", C.c_double),
                ("torque", C.c_double), ("done", C.c_int)]


class Policy(C.Structure):
    _fields_ = [("n_actions", C.c_int), ("decision_period", C.c_int), ("w", C.POINTER(C.c_double)),
                ("levels", C.POINTER(C.c_double)), ("theta_min", C.c_double), ("theta_max", C.c_double),
                ("omega_max", C.c_double), ("greedy", C.c_int)]


class Buffers(C.Structure):
    _fields_ = [("capacity", C.c_int), ("features", C.POINTER(C.c_double)), ("actions", C.POINTER(C.c_int32)),
                ("rewards", C.POINTER(C.c_double)), ("probs", C.POINTER(C.c_double)),
                ("step_capacity", C.c_int), ("step_rewards", C.POINTER(C.c_double)),
                ("step_theta", C.POINTER(C.c_double))]


class EpisodeC(C.Structure):
    _fields_ = [("n_steps", C.c_int), ("n_decisions", C.c_int), ("poured", C.c_double), ("spilled", C.c_double),
                ("remaining", C.c_double), ("finish_time", C.c_double), ("ret", C.c_double),
                ("reward_sum", C.c_double), ("max_theta", C.c_double)]


def library_path() -> Path:
    """Where libpoursim.so is; EnvError naming every place looked at if nowhere."""
    looked = []
    env = os.environ.get("POUR_SIM_LIB")
    if env:
        return Path(env)  # explicit: used as given, a wrong path fails loudly at load
    root = Path(__file__).resolve().parents[2]
    cands = []
    if os.environ.get("POUR_BUILD_DIR"):
        cands.append(Path(os.environ["POUR_BUILD_DIR"]) / "lib" / "libpoursim.so")
    cands += [root / "build" / "host" / "lib" / "libpoursim.so"]
    cands += [Path(p) for p in sorted(glob.glob(str(root / "build" / "*" / "lib" / "libpoursim.so")))]
    for c in cands:
        looked.append(str(c))
        if c.is_file():
            return c
    raise envs.EnvError("libpoursim.so not found (looked in: " + ", ".join(looked) + "); build it with "
                        "'cmake --build build/host --target poursim_shared' or set POUR_SIM_LIB")


_LIB: Any = None


def load_library() -> Any:
    global _LIB
    if _LIB is not None:
        return _LIB
    path = library_path()
    try:
        lib = C.CDLL(str(path))
    except OSError as exc:
        raise envs.EnvError(f"cannot load the simulator library {path}: {exc}") from exc
    try:
        lib.poursim_default_config.restype = Config
        lib.poursim_config_set.argtypes = [C.POINTER(Config), C.c_char_p, C.c_char_p, C.c_char_p, C.c_size_t]
        lib.poursim_config_validate.argtypes = [C.POINTER(Config), C.c_char_p, C.c_size_t]
        lib.poursim_create.argtypes = [C.POINTER(Config), C.c_char_p, C.c_size_t]
        lib.poursim_create.restype = C.c_void_p
        lib.poursim_destroy.argtypes = [C.c_void_p]
        lib.poursim_reset.argtypes = [C.c_void_p, C.c_uint32]
        lib.poursim_step.argtypes = [C.c_void_p, C.c_double, C.POINTER(Obs)]
        lib.poursim_observe.argtypes = [C.c_void_p, C.POINTER(Obs)]
        lib.poursim_observe.restype = None
        lib.poursim_rollout.argtypes = [C.c_void_p, C.POINTER(Policy), C.c_uint32, C.POINTER(Buffers),
                                        C.POINTER(EpisodeC)]
    except AttributeError as exc:
        raise envs.EnvError(f"{path} is not a usable libpoursim (missing symbol: {exc})") from exc
    _LIB = lib
    return lib


def make_config(options: dict[str, Any] | None) -> Config:
    """Defaults of the paper's scene, with options (the simulator's config keys) set over them."""
    lib = load_library()
    cfg = lib.poursim_default_config()
    err = C.create_string_buffer(ERR_LEN)
    for k, v in (options or {}).items():
        val = str(v).lower() if isinstance(v, bool) else repr(v) if isinstance(v, float) else str(v)
        if lib.poursim_config_set(C.byref(cfg), str(k).encode(), val.encode(), err, ERR_LEN) != 0:
            raise envs.EnvError(f"simulator option {k} = {v!r}: {err.value.decode(errors='replace')}")
    if lib.poursim_config_validate(C.byref(cfg), err, ERR_LEN) != 0:
        raise envs.EnvError(f"simulator config: {err.value.decode(errors='replace')}")
    return cfg


def _check_norm(cfg: Config) -> None:
    want = (envs.THETA_MIN_RAD, envs.THETA_MAX_RAD, envs.OMEGA_MAX_RAD_S)
    have = (cfg.obs_theta_min, cfg.obs_theta_max, cfg.obs_omega_max)
    if any(abs(a - b) > 1e-9 for a, b in zip(want, have)):
        raise envs.EnvError(f"simulator normalisation {have} differs from the trainer's {want}")


class _World:
    def __init__(self, options: dict[str, Any] | None):
        self.lib = load_library()
        self.cfg = make_config(options)
        _check_norm(self.cfg)
        err = C.create_string_buffer(ERR_LEN)
        self.world = self.lib.poursim_create(C.byref(self.cfg), err, ERR_LEN)
        if not self.world:
            raise envs.EnvError(f"poursim_create: {err.value.decode(errors='replace')}")
        self.tau_max_nm = float(self.cfg.tau_max)

    def __del__(self) -> None:
        if getattr(self, "world", None) and _LIB is not None:
            _LIB.poursim_destroy(self.world)
            self.world = None


class SimEnv(_World):
    """rollout(w, seed, greedy) -> envs.Episode, one whole episode in C."""

    def __init__(self, n_actions: int, decision_period_ms: int, episode_s: float,
                 options: dict[str, Any] | None = None):
        opts = dict(options or {})
        opts.setdefault("episode_s", episode_s)
        super().__init__(opts)
        if abs(self.cfg.dt - 1e-3) > 1e-12:
            raise envs.EnvError(f"simulator dt = {self.cfg.dt}: the policy's decision period assumes 1 ms ticks")
        self.n_actions, self.period = n_actions, decision_period_ms
        self.levels = np.ascontiguousarray(reinforce.action_levels(n_actions), dtype=np.float64)
        steps = int(round(self.cfg.episode_s / self.cfg.dt))
        self.n_dec = -(-steps // decision_period_ms)

    def rollout(self, w: np.ndarray, seed: int, greedy: bool) -> envs.Episode:
        w = np.ascontiguousarray(w, dtype=np.float64)
        if w.shape != (N_FEATURES, self.n_actions):
            raise envs.EnvError(f"W has shape {w.shape}, expected ({N_FEATURES}, {self.n_actions})")
        dp = C.POINTER(C.c_double)
        pol = Policy(self.n_actions, self.period, w.ctypes.data_as(dp), self.levels.ctypes.data_as(dp),
                     self.cfg.obs_theta_min, self.cfg.obs_theta_max, self.cfg.obs_omega_max, int(bool(greedy)))
        x = np.zeros((self.n_dec, N_FEATURES))
        acts = np.zeros(self.n_dec, dtype=np.int32)
        rews = np.zeros(self.n_dec)
        buf = Buffers(self.n_dec, x.ctypes.data_as(dp), acts.ctypes.data_as(C.POINTER(C.c_int32)),
                      rews.ctypes.data_as(dp), None, 0, None, None)
        ep = EpisodeC()
        rc = self.lib.poursim_rollout(self.world, C.byref(pol), C.c_uint32(int(seed) & 0xFFFFFFFF), C.byref(buf),
                                      C.byref(ep))
        if rc != 0:
            raise envs.EnvError(f"poursim_rollout failed with status {rc} (seed {seed})")
        metrics = {"v_target": ep.poured, "v_spill": ep.spilled, "v_rotating": ep.remaining,
                   "finish_s": ep.finish_time, "return": ep.ret, "reward_sum": ep.reward_sum,
                   "max_theta": ep.max_theta}
        return envs.Episode(x, acts.astype(np.int64), rews, metrics, int(seed))


class SimStepper(_World):
    """Tick-by-tick access for the Gymnasium env; torques pass the firmware's safety envelope."""

    def reset(self, seed: int) -> None:
        rc = self.lib.poursim_reset(self.world, C.c_uint32(int(seed) & 0xFFFFFFFF))
        if rc != 0:
            raise envs.EnvError(f"poursim_reset failed with status {rc}")
        self.obs = Obs()
        self.lib.poursim_observe(self.world, C.byref(self.obs))
        self.safety = fp.SafetyEnvelope()

    @property
    def v_tgt(self) -> float:
        return float(self.obs.v_target)

    @property
    def v_spill(self) -> float:
        return float(self.obs.v_spill)

    def features(self) -> np.ndarray:
        o = self.obs
        return envs.normalise(o.theta, o.omega, o.v_rotating, o.v_target, o.v_spill)

    def advance(self, level: float, ticks: int) -> float:
        req = fp.float_to_q15(level)
        r = 0.0
        for _ in range(ticks):
            t = max(-2e9, min(2e9, self.obs.theta * 1e6))
            theta_urad = int(math.copysign(math.floor(abs(t) + 0.5), t))  # C's round(): half away from 0
            cmd = self.safety.apply(req, theta_urad)
            rc = self.lib.poursim_step(self.world, cmd / 32768.0, C.byref(self.obs))
            if rc != 0:
                raise envs.EnvError(f"poursim_step failed with status {rc}")
            r += self.obs.reward
        return r
