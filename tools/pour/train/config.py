# SPDX-License-Identifier: MIT
"""Training configuration: one TOML file fully determines a run (seed -> identical run).

Every value is checked once, at load time; a bad value raises ConfigError naming the key, its
value and what is allowed, so a typo never turns into a silent default or a crash mid-run.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pour.policy.weights_h import FEATURE_NAMES


class ConfigError(ValueError):
    """A configuration file or value that cannot be used."""


@dataclass(frozen=True)
class PolicyConfig:
    n_actions: int = 11            # torque levels evenly spaced in [-1, 1] x tau_max, 2..16
    decision_period_ms: int = 10   # a new action every this many 1 ms ticks
    init: str = "zeros"            # "zeros": every parameter 0 (param "full": uniform random actions, as the paper);
                                   # "random": i.i.d. normal(0, init_scale^2), seeded by the run's seed
    init_beta: list = field(default_factory=list)  # param "feedback", init "beta": the 6 initial beta values
    param: str = "full"            # "full": W itself; "feedback": W from a linear feedback u(x) (reinforce.py)
    sharpness: float = 4.0         # "feedback": c in logit_a = -c (L_a - u(x))^2
    init_scale: float = 0.0        # init "random": standard deviation of each initial parameter


@dataclass(frozen=True)
class AlgoConfig:
    kind: str = "pg"               # "vanilla" (paper eq. 19), "pg" (the improved update) or "ars" (random
                                   # search on greedy rollouts, options in [ars]; uses gamma and reward_scale)
    batch_episodes: int = 16       # episodes per update (vanilla: the paper uses 1)
    gamma: float = 0.9995          # discount per 1 ms tick (per decision: gamma ** period)
    lr: float = 0.05               # learning rate at the first iteration
    lr_final: float = -1.0         # linearly decayed to this at the last iteration (< 0: constant lr)
    optimizer: str = "adam"        # "adam", "sgd" or "natural" (a natural-gradient step of KL max_kl)
    reward_to_go: bool = True      # weight log pi(a_t) by the return from t on, not R(tau)
    baseline: str = "loo"          # "none", "loo" (time-indexed mean of the others in the batch)
    normalize_advantages: bool = True
    entropy_coef: float = 0.01     # bonus on the mean policy entropy at the first iteration
    entropy_coef_final: float = 0.0  # linearly annealed to this at the last iteration
    grad_clip: float = 0.0         # clip the gradient's L2 norm to this (0 = off)
    max_kl: float = 0.0            # trust region: halve the step until the mean KL(old || new) over
                                   # the batch's states is <= this [nats] (0 = off)
    max_kl_final: float = -1.0     # decayed geometrically to this at the last iteration (< 0: constant)
    rollback: float = 0.0          # undo a step when the next batch's mean return falls below the best
                                   # batch's by more than this fraction (+ 2 standard errors); 0 = off
    rollback_shrink: float = 0.2   # each undone step multiplies the trust region (max_kl) by this
    rollback_from: int = 0         # no step is undone before this iteration (the first steps may cross a
                                   # valley on their way out of the initial policy's basin)
    reward_scale: float = 1.0      # rewards are multiplied by this before anything else


@dataclass(frozen=True)
class ArsConfig:
    """Augmented random search (Mania, Guy & Recht 2018, V1-t, or V2-t with normalize_states) over the policy's
    parameters (ars.py)."""
    directions: int = 8            # random directions per iteration, each rolled out at +noise and -noise
    top: int = 4                   # the directions with the best max(R+, R-) that make the step
    step_size: float = 0.02        # alpha at the first iteration (the step is alpha / (top * sigma_R) sum ...)
    step_size_final: float = -1.0  # linearly decayed to this at the last iteration (< 0: constant)
    noise: float = 0.03            # nu: the perturbation's standard deviation per parameter
    noise_final: float = -1.0      # decayed geometrically to this at the last iteration (< 0: constant)
    episodes_per_direction: int = 1  # rigs per perturbed policy; the same rigs for +, - and every direction
    normalize_states: bool = False  # V2-t: search in the coordinates of the states standardised by the running
                                   # mean and std of every training rollout's features (ars.py)
    state_std_min: float = 0.01    # floor of that std (a feature that barely moves, V_spill, is not blown up)
    features: list = field(default_factory=list)  # the features whose gains the search moves (names of
                                   # weights_h.FEATURE_NAMES); the others keep their initial gains. [] = all


@dataclass(frozen=True)
class CemConfig:
    """The cross-entropy method over the policy's parameters (tools/pour/train/ars.py)."""
    population: int = 16           # candidates per iteration, drawn from normal(mean, diag(std^2))
    elites: int = 4                # the best candidates, whose mean and spread become the next distribution
    init_std: float = 2.0          # the distribution's standard deviation per parameter at the start
    min_std: float = 0.05          # floor of the standard deviation (keeps exploring; > 0)
    episodes_per_candidate: int = 1  # rigs per candidate; the same rigs for every candidate of an iteration


@dataclass(frozen=True)
class EvalConfig:
    every: int = 5                 # greedy evaluation every this many iterations (and the last)
    episodes: int = 8              # validation episodes per evaluation (seeds disjoint from training)
    select_best: bool = True       # keep the weights with the best greedy validation score
    collapse: float = 0.0          # algo.kind 'ars' or 'cem': stop when the validation score falls this fraction
                                   # of |best| below the best (plus its standard error) ...
    collapse_patience: int = 3     # ... at this many evaluations in a row; the best checkpoint is kept


@dataclass(frozen=True)
class EnvConfig:
    kind: str = "sim"              # "sim" (libpoursim through tools/pour/sim/poursim.py) or "toy"
    episode_s: float = 10.0        # episode length [s]
    options: dict = field(default_factory=dict)  # passed to the simulator as is (scene, K's, tau_max)


@dataclass(frozen=True)
class TrainConfig:
    seed: int = 1
    iterations: int = 100
    workers: int = 2
    policy: PolicyConfig = PolicyConfig()
    algo: AlgoConfig = AlgoConfig()
    ars: ArsConfig = ArsConfig()
    cem: CemConfig = CemConfig()
    eval: EvalConfig = EvalConfig()
    env: EnvConfig = EnvConfig()

    def to_dict(self) -> dict[str, Any]:
        """Every value, except those of a method the run does not use ([ars] and [cem] unless algo.kind
        names them, policy.init_scale unless init = 'random', eval.collapse* while off, ars.normalize_states,
        ars.state_std_min and ars.features while off): a config that
        does not use them keeps its digest, and the header it exports keeps its bytes."""
        d = dataclasses.asdict(self)
        for method in ("ars", "cem"):
            if self.algo.kind != method:
                del d[method]
        if self.eval.collapse == 0.0:
            del d["eval"]["collapse"], d["eval"]["collapse_patience"]
        if self.policy.init != "random":
            del d["policy"]["init_scale"]
        if "ars" in d:
            if not self.ars.normalize_states:
                del d["ars"]["normalize_states"], d["ars"]["state_std_min"]
            if not self.ars.features:
                del d["ars"]["features"]
        return d

    def digest(self) -> str:
        """sha256 of the canonical JSON of every value but `workers` (which never changes results)."""
        d = self.to_dict()
        del d["workers"]
        blob = json.dumps(d, sort_keys=True, separators=(",", ":")).encode()
        return hashlib.sha256(blob).hexdigest()


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
    _check(a.kind in ("vanilla", "pg", "ars", "cem"),
           f"algo.kind = {a.kind!r}: expected 'vanilla', 'pg', 'ars' or 'cem'")
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
