# SPDX-License-Identifier: MIT
"""What a training config holds: its sections, their fields and defaults, and the run's digest.

The training methods (pour.train.methods' registry) read these; config.py parses a TOML file into them
and checks every value, the method's name against the registry's.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from typing import Any


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
    kind: str = "pg"               # the training method, a name of pour.train.methods.METHODS: "vanilla" (paper
                                   # eq. 19), "pg" (the improved update), "ars" or "cem" (random search on greedy
                                   # rollouts, options in [ars] or [cem]; they use gamma and reward_scale)
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
