# SPDX-License-Identifier: MIT
"""Training configuration: one TOML file fully determines a run (seed -> identical run).

Every value is checked once, at load time; a bad value raises ConfigError naming the key, its
value and what is allowed, so a typo never turns into a silent default or a crash mid-run.
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path
from typing import Any

from pour.policy.weights_h import FEATURE_NAMES
from pour.train import methods
from pour.train.settings import (AlgoConfig, ArsConfig, CemConfig, ConfigError, EnvConfig, EvalConfig,  # noqa: F401
                                 PolicyConfig, TrainConfig)


_SECTIONS = {"policy": PolicyConfig, "algo": AlgoConfig, "ars": ArsConfig, "cem": CemConfig, "eval": EvalConfig, "env": EnvConfig}


def _typed(section: str, key: str, value: Any, want: Any) -> Any:
    name = f"{section}.{key}" if section else key
    if isinstance(want, bool):
        if not isinstance(value, bool):
            raise ConfigError(f"{name} = {value!r}: expected true or false")
        return value
    if isinstance(want, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{name} = {value!r}: expected an integer")
        return value
    if isinstance(want, float):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{name} = {value!r}: expected a number")
        if not math.isfinite(value):
            raise ConfigError(f"{name} = {value!r}: expected a finite number")
        return float(value)
    if isinstance(want, str):
        if not isinstance(value, str):
            raise ConfigError(f"{name} = {value!r}: expected a string")
        return value
    if isinstance(want, list):
        if not isinstance(value, list):
            raise ConfigError(f"{name} = {value!r}: expected an array")
        return list(value)
    if isinstance(want, dict):
        if not isinstance(value, dict):
            raise ConfigError(f"{name} = {value!r}: expected a table")
        return dict(value)
    raise ConfigError(f"{name}: unsupported type")  # pragma: no cover - a bug in this module


def _build(cls: type, section: str, table: dict) -> Any:
    defaults = cls()
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise ConfigError(f"[{section}] unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    kwargs = {k: _typed(section, k, v, getattr(defaults, k)) for k, v in table.items()}
    return dataclasses.replace(defaults, **kwargs)


def _check(cond: bool, msg: str) -> None:
    if not cond:
        raise ConfigError(msg)


def validate(cfg: TrainConfig) -> TrainConfig:
    """Checks every value's range; returns cfg unchanged or raises ConfigError."""
    _check(0 <= cfg.seed < 2**32, f"seed = {cfg.seed}: expected 0 <= seed < 2^32")
    _check(1 <= cfg.iterations <= 1_000_000, f"iterations = {cfg.iterations}: expected 1..1000000")
    _check(1 <= cfg.workers <= 64, f"workers = {cfg.workers}: expected 1..64")
    p, a, e, v = cfg.policy, cfg.algo, cfg.eval, cfg.env
    _check(2 <= p.n_actions <= 16, f"policy.n_actions = {p.n_actions}: expected 2..16")
    _check(1 <= p.decision_period_ms <= 1000,
           f"policy.decision_period_ms = {p.decision_period_ms}: expected 1..1000")
    _check(p.init in ("zeros", "beta", "random"),
           f"policy.init = {p.init!r}: expected 'zeros', 'beta' or 'random'")
    _check(0.0 <= p.init_scale <= 100.0, f"policy.init_scale = {p.init_scale}: expected 0 <= scale <= 100")
    _check((p.init == "random") == (p.init_scale > 0),
           f"policy.init_scale = {p.init_scale}: expected > 0 exactly when policy.init = 'random' "
           f"(init = {p.init!r})")
    if p.init == "beta":
        _check(p.param == "feedback", "policy.init = 'beta' needs policy.param = 'feedback'")
        _check(len(p.init_beta) == 6 and all(isinstance(b, (int, float)) and not isinstance(b, bool)
                                             and math.isfinite(b) for b in p.init_beta),
               f"policy.init_beta = {p.init_beta!r}: expected 6 finite numbers (theta, omega, V_rot, V_tgt, "
               "V_spill, bias)")
    _check(p.param in ("full", "feedback"), f"policy.param = {p.param!r}: expected 'full' or 'feedback'")
    _check(0.0 < p.sharpness <= 1000.0, f"policy.sharpness = {p.sharpness}: expected 0 < c <= 1000")
    _check(a.kind in methods.METHODS, methods.unknown(a.kind))
    if a.kind in ("ars", "cem"):
        _validate_search(cfg)
    _check(0.0 <= e.collapse <= 10.0, f"eval.collapse = {e.collapse}: expected 0 <= fraction <= 10 (0 = off)")
    _check(e.collapse == 0 or a.kind in ("ars", "cem"),
           f"eval.collapse = {e.collapse}: only for algo.kind 'ars' or 'cem' (kind 'pg' has algo.rollback)")
    _check(e.collapse_patience >= 1, f"eval.collapse_patience = {e.collapse_patience}: expected >= 1")
    if a.kind == "vanilla":
        paper = {"lr_final": -1.0, "reward_to_go": False, "baseline": "none", "normalize_advantages": False, "entropy_coef": 0.0,
                 "entropy_coef_final": 0.0, "optimizer": "sgd", "grad_clip": 0.0, "max_kl": 0.0,
                 "max_kl_final": -1.0, "rollback": 0.0}
        for k, want in paper.items():
            _check(getattr(a, k) == want, f"algo.kind = 'vanilla' is the paper's update: algo.{k} must be {want!r} "
                                       f"(got {getattr(a, k)!r}); use algo.kind = 'pg' to change it")
        _check(p.param == "full", f"algo.kind = 'vanilla' is the paper's update: policy.param must be 'full' "
                                  f"(got {p.param!r})")
    _check(1 <= a.batch_episodes <= 4096, f"algo.batch_episodes = {a.batch_episodes}: expected 1..4096")
    _check(0.0 < a.gamma <= 1.0, f"algo.gamma = {a.gamma}: expected 0 < gamma <= 1")
    _check(0.0 < a.lr <= 10.0, f"algo.lr = {a.lr}: expected 0 < lr <= 10")
    _check(a.lr_final < 0 or a.lr_final <= a.lr,
           f"algo.lr_final = {a.lr_final}: expected <= algo.lr ({a.lr}), or negative for a constant lr")
    _check(a.optimizer in ("adam", "sgd", "natural"),
           f"algo.optimizer = {a.optimizer!r}: expected 'adam', 'sgd' or 'natural'")
    _check(a.optimizer != "natural" or a.max_kl > 0,
           "algo.optimizer = 'natural' needs algo.max_kl > 0 (the KL of each step)")
    _check(a.max_kl_final < 0 or 0 < a.max_kl_final <= a.max_kl,
           f"algo.max_kl_final = {a.max_kl_final}: expected 0 < max_kl_final <= algo.max_kl ({a.max_kl}), or "
           "negative for a "
           "constant bound")
    _check(a.baseline in ("none", "loo"), f"algo.baseline = {a.baseline!r}: expected 'none' or 'loo'")
    _check(a.baseline == "none" or a.batch_episodes >= 2,
           f"algo.baseline = {a.baseline!r} needs algo.batch_episodes >= 2 (got {a.batch_episodes})")
    _check(a.entropy_coef >= 0.0, f"algo.entropy_coef = {a.entropy_coef}: expected >= 0")
    _check(a.entropy_coef_final >= 0.0, f"algo.entropy_coef_final = {a.entropy_coef_final}: expected >= 0")
    _check(a.grad_clip >= 0.0, f"algo.grad_clip = {a.grad_clip}: expected >= 0 (0 = off)")
    _check(0.0 <= a.max_kl <= 10.0, f"algo.max_kl = {a.max_kl}: expected 0 <= max_kl <= 10 [nats] (0 = off)")
    _check(0.0 <= a.rollback <= 1.0, f"algo.rollback = {a.rollback}: expected 0..1 (0 = off)")
    _check(a.rollback == 0 or a.max_kl > 0, "algo.rollback needs algo.max_kl > 0 (the trust region it shrinks)")
    _check(a.rollback_from >= 0, f"algo.rollback_from = {a.rollback_from}: expected >= 0")
    _check(0.0 < a.rollback_shrink <= 1.0, f"algo.rollback_shrink = {a.rollback_shrink}: expected 0 < s <= 1")
    _check(a.reward_scale > 0.0, f"algo.reward_scale = {a.reward_scale}: expected > 0")
    _check(e.every >= 1, f"eval.every = {e.every}: expected >= 1")
    _check(0 <= e.episodes <= 1024, f"eval.episodes = {e.episodes}: expected 0..1024")
    _check(v.kind in ("sim", "toy"), f"env.kind = {v.kind!r}: expected 'sim' or 'toy'")
    _check(0.0 < v.episode_s <= 60.0, f"env.episode_s = {v.episode_s}: expected 0 < s <= 60")
    steps = round(v.episode_s * 1000)
    _check(steps % p.decision_period_ms == 0,
           f"env.episode_s = {v.episode_s} is not a whole number of decision periods "
           f"({p.decision_period_ms} ms)")
    return cfg


def _validate_search(cfg: TrainConfig) -> None:
    r, c, a = cfg.ars, cfg.cem, cfg.algo
    _check(1 <= r.directions <= 256, f"ars.directions = {r.directions}: expected 1..256")
    _check(1 <= r.top <= r.directions, f"ars.top = {r.top}: expected 1..ars.directions ({r.directions})")
    _check(0.0 < r.step_size <= 10.0, f"ars.step_size = {r.step_size}: expected 0 < alpha <= 10")
    _check(r.step_size_final < 0 or r.step_size_final <= r.step_size,
           f"ars.step_size_final = {r.step_size_final}: expected <= ars.step_size ({r.step_size}), or negative "
           "for a constant step")
    _check(0.0 < r.noise <= 10.0, f"ars.noise = {r.noise}: expected 0 < nu <= 10")
    _check(r.noise_final < 0 or 0 < r.noise_final <= r.noise,
           f"ars.noise_final = {r.noise_final}: expected 0 < nu_final <= ars.noise ({r.noise}), or negative for a "
           "constant noise")
    _check(1 <= r.episodes_per_direction <= 64,
           f"ars.episodes_per_direction = {r.episodes_per_direction}: expected 1..64")
    _check(0.0 < r.state_std_min <= 1.0, f"ars.state_std_min = {r.state_std_min}: expected 0 < std <= 1")
    _check(not r.normalize_states or a.kind == "ars",
           f"ars.normalize_states = true: only for algo.kind = 'ars' (got {a.kind!r})")
    _check(all(isinstance(f, str) and f in FEATURE_NAMES for f in r.features) and len(set(r.features)) == len(r.features),
           f"ars.features = {r.features!r}: expected distinct names out of {list(FEATURE_NAMES)} ([] = all)")
    _check(not r.features or a.kind == "ars", f"ars.features = {r.features!r}: only for algo.kind = 'ars' (got {a.kind!r})")
    _check(2 <= c.population <= 1024, f"cem.population = {c.population}: expected 2..1024")
    _check(1 <= c.elites < c.population,
           f"cem.elites = {c.elites}: expected 1..cem.population - 1 ({c.population - 1})")
    _check(0.0 < c.init_std <= 100.0, f"cem.init_std = {c.init_std}: expected 0 < std <= 100")
    _check(0.0 < c.min_std <= c.init_std, f"cem.min_std = {c.min_std}: expected 0 < min_std <= cem.init_std "
                                          f"({c.init_std})")
    _check(1 <= c.episodes_per_candidate <= 64,
           f"cem.episodes_per_candidate = {c.episodes_per_candidate}: expected 1..64")
    # The policy-gradient options have no meaning for random search: refuse them rather than ignore them.
    for k in ("max_kl", "rollback", "grad_clip"):
        _check(getattr(a, k) == 0.0, f"algo.kind = {a.kind!r} has no algo.{k} (got {getattr(a, k)!r}); its "
                                     f"options are in [{a.kind}]")


def _with_rig(env: dict) -> dict:
    """[env] with its rig (a name of pour.sim.rigs: configs/sim/<rig>.cfg) read into the options, ahead of
    those written in [env.options]; a key in both is refused (the rig file is its one place)."""
    if "rig" not in env:
        return env
    from pour.sim import rigs
    env = dict(env)
    rig = env.pop("rig")
    if not isinstance(rig, str):
        raise ConfigError(f"[env] rig = {rig!r}: expected a rig name ({', '.join(rigs.names())})")
    try:
        options = rigs.load(rig)
    except rigs.RigError as e:
        raise ConfigError(f"[env] rig: {e}") from None
    own = env.get("options", {})
    if not isinstance(own, dict):
        raise ConfigError("[env.options]: expected a table")
    twice = sorted(set(own) & set(options))
    if twice:
        raise ConfigError(f"[env.options] {', '.join(twice)}: already set by [env] rig = {rig!r} "
                          f"(configs/sim/{rigs.RIGS[rig]})")
    env["options"] = {**options, **own}
    return env


def from_dict(data: dict) -> TrainConfig:
    """Builds and validates a config from a parsed TOML document."""
    if not isinstance(data, dict):
        raise ConfigError("config: expected a table at the top level")
    top = {k: v for k, v in data.items() if k not in _SECTIONS}
    known_top = {"seed", "iterations", "workers"}
    unknown = sorted(set(top) - known_top)
    if unknown:
        raise ConfigError(f"unknown top-level key(s) {', '.join(unknown)}; known: "
                          f"{', '.join(sorted(known_top | set(_SECTIONS)))}")
    base = TrainConfig()
    kwargs: dict[str, Any] = {k: _typed("", k, v, getattr(base, k)) for k, v in top.items()}
    for name, cls in _SECTIONS.items():
        if name in data:
            if not isinstance(data[name], dict):
                raise ConfigError(f"[{name}]: expected a table")
            kwargs[name] = _build(cls, name, _with_rig(data[name]) if name == "env" else data[name])
    return validate(dataclasses.replace(base, **kwargs))


def load(path: str | Path) -> TrainConfig:
    """Reads a TOML config file; every problem raises ConfigError with the file name."""
    path = Path(path)
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read config ({exc.strerror})") from exc
    try:
        data = tomllib.loads(text.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from exc
    try:
        return from_dict(data)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from exc


def with_overrides(cfg: TrainConfig, **changes: Any) -> TrainConfig:
    """A copy with top-level fields replaced (e.g. seed, iterations), validated again."""
    return validate(dataclasses.replace(cfg, **changes))
