# SPDX-License-Identifier: MIT
"""Stable-Baselines3's PPO on pour/Pour-v0, restricted to the policy class the firmware runs, exported to
weights.h through pour-export's own code.

The firmware runs softmax-linear policies only, pi(a|x) = softmax(x.W) over the six features (the five
normalised state variables and a bias): a fixed-point dot product per action fits a Cortex-M4's 1 ms step
with a bounded, checkable worst case. So the actor here has no hidden layer: SB3's MlpPolicy with
net_arch pi=[] puts one nn.Linear(5, n_actions) on the observation under a categorical distribution,
which is that class exactly (its weight and bias are W's rows). The critic is an MLP: it only trains and
is not exported. For comparison, --actor mlp trains SB3's default actor (two tanh layers of 64): what a
general-purpose library reaches; it has no W, so its run is validated and evaluated through the Gymnasium env
(the same simulator and firmware pipeline, stepped from Python) and never becomes a weights.h.

    ./scripts/setup.sh --with-sb3                                      # the extra: SB3 and torch
    .venv/bin/python -m pour.examples.sb3_ppo --steps 200000 --out runs/sb3_ppo
    .venv/bin/pour-export runs/sb3_ppo --out policy/weights.h          # or --header here
    .venv/bin/python -m pour.examples.sb3_ppo --init-header policy/weights.h ...   # fine-tune the shipped W
    .venv/bin/python -m pour.examples.sb3_ppo --like configs/train/vanilla11.toml --actor mlp --out runs/mlp

    from pour.examples import sb3_ppo
    w = sb3_ppo.train_linear(steps=200_000, seed=1)                    # W [6][n_actions], float
    w = sb3_ppo.train_linear(steps=20_000, init_w=sb3_ppo.header_weights("policy/weights.h"))
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Sequence

import gymnasium as gym
import numpy as np

from pour import atomic, cli
from pour.policy import export, weights_h
from pour.sim import episode, gym_env

ENV_ID = "pour/Pour-v0"
# PPO's settings: one rollout of 1024 decisions (10.24 s of pour) per update, 10 epochs of minibatches of 256.
PPO_DEFAULTS: dict[str, Any] = {"n_steps": 1024, "batch_size": 256, "n_epochs": 10, "gamma": 0.99,
                                "learning_rate": 3e-4, "ent_coef": 0.0}
CRITIC = [64, 64]
# The actor's hidden layers: none (softmax-linear, the firmware's class) or SB3's default MLP (two of 64, tanh:
# what a general-purpose library reaches; it cannot become a weights.h).
ACTORS: dict[str, list[int]] = {"linear": [], "mlp": [64, 64]}


class ExampleError(RuntimeError):
    """The sb3 extra is missing, or the run cannot be written."""


def _sb3():
    try:
        import stable_baselines3
        import torch
    except ImportError as exc:
        raise ExampleError(f"{exc.name} is not installed: this example needs the sb3 extra "
                           "(./scripts/setup.sh --with-sb3, or pip install './tools[sb3]')") from None
    return stable_baselines3, torch


def make_model(env: Any, seed: int, actor: str = "linear", **ppo_kwargs: Any) -> Any:
    """A PPO whose actor is softmax-linear (no hidden layer; actor 'mlp': SB3's two tanh layers of 64) and
    whose critic is an MLP, on CPU, seeded."""
    if actor not in ACTORS:
        raise ExampleError(f"actor {actor!r}: expected one of {', '.join(ACTORS)}")
    sb3, torch = _sb3()
    # One thread: the networks are tiny, and a single-threaded CPU run is reproducible from its seed.
    torch.set_num_threads(1)
    kwargs = dict(PPO_DEFAULTS, **ppo_kwargs)
    return sb3.PPO("MlpPolicy", env, seed=seed, device="cpu", verbose=0,
                   policy_kwargs={"net_arch": {"pi": list(ACTORS[actor]), "vf": CRITIC}}, **kwargs)


def mlp_layers(model: Any) -> list[np.ndarray]:
    """The actor as gym_env.mlp_actor's layers [W1, b1, ..., W_out, b_out] (W [inputs][outputs], float64):
    its hidden linear layers, then the action layer."""
    linears = [m for m in model.policy.mlp_extractor.policy_net if hasattr(m, "weight")]
    out = []
    for layer in [*linears, model.policy.action_net]:
        out += [layer.weight.detach().cpu().numpy().astype(np.float64).T,
                layer.bias.detach().cpu().numpy().astype(np.float64)]
    return out


def linear_weights(model: Any) -> np.ndarray:
    """The actor as the firmware's W [6][n_actions]: the linear layer's weight (transposed) over its bias."""
    if getattr(model.policy.mlp_extractor, "latent_dim_pi", None) != model.observation_space.shape[0]:
        raise ExampleError("the policy's actor has a hidden layer: it is not softmax-linear")
    layer = model.policy.action_net
    weight = layer.weight.detach().cpu().numpy().astype(np.float64)
    bias = layer.bias.detach().cpu().numpy().astype(np.float64)
    return np.vstack([weight.T, bias[None, :]])


def set_linear_weights(model: Any, w: np.ndarray) -> None:
    """Sets the softmax-linear actor to W [6][n_actions] (the inverse of linear_weights, to float32)."""
    _, torch = _sb3()
    layer = model.policy.action_net
    w = np.asarray(w, dtype=np.float64)
    if w.shape != (layer.in_features + 1, layer.out_features):
        raise ExampleError(f"W is {w.shape[0]} x {w.shape[1]}: this actor takes "
                           f"{layer.in_features + 1} x {layer.out_features}")
    with torch.no_grad():
        layer.weight.copy_(torch.as_tensor(w[:-1].T, dtype=layer.weight.dtype))
        layer.bias.copy_(torch.as_tensor(w[-1], dtype=layer.bias.dtype))


def header_weights(path: str | Path) -> np.ndarray:
    """W of a weights.h, to start PPO from: its float reference if it has one, else the dequantised table."""
    try:
        h = weights_h.parse_weights_h(path)
    except OSError as exc:
        raise ExampleError(f"{path}: cannot read ({exc.strerror})") from None
    return np.asarray(h.w_float if h.w_float is not None else h.w_dequantized, dtype=np.float64)


def _progress_callback(total: int, quiet: bool) -> Any:
    from stable_baselines3.common.callbacks import BaseCallback

    class Progress(BaseCallback):
        def _on_training_start(self) -> None:
            self.bar = cli.bar(total, desc="PPO", quiet=quiet, unit="step")

        def _on_step(self) -> bool:
            self.bar.update(self.training_env.num_envs)
            return True

        def _on_training_end(self) -> None:
            self.bar.close()

    return Progress()


def train(steps: int, seed: int = 1, env_id: str = ENV_ID, quiet: bool = True, env_kwargs: dict | None = None,
          init_w: np.ndarray | None = None, **ppo_kwargs: Any) -> tuple[Any, np.ndarray]:
    """Trains PPO for `steps` env steps (decisions) on env_id, from SB3's initial actor or from init_w
    [6][n_actions]; returns (the SB3 model, its W [6][n_actions])."""
    if steps < 1:
        raise ExampleError(f"steps = {steps}: expected at least 1")
    env = gym.make(env_id, **(env_kwargs or {}))
    model = make_model(env, seed, **ppo_kwargs)
    if init_w is not None:
        set_linear_weights(model, init_w)
    model.learn(total_timesteps=int(steps), callback=_progress_callback(int(steps), quiet))
    return model, linear_weights(model)


def train_linear(steps: int, seed: int = 1, env_id: str = ENV_ID, **kwargs: Any) -> np.ndarray:
    """W [6][n_actions] of a PPO run (train), for callers that want the weights only."""
    return train(steps, seed, env_id, **kwargs)[1]


def mlp_validation(cfg: Any, layers: Sequence[np.ndarray], seeds: Sequence[int]) -> dict[str, float]:
    """An MLP actor greedy on the validation seeds through the Gymnasium env (cfg's rig and episode length):
    the log's eval_* columns, as rundir.greedy_validation gives them for a W through the C rollouts (the
    score is the env's reward, which has no reversal cost)."""
    env = gym_env.PourEnv(cfg.env.kind, cfg.policy.n_actions, cfg.policy.decision_period_ms, cfg.env.episode_s,
                          cfg.env.options)
    act = gym_env.mlp_actor(layers)
    ms = [gym_env.greedy_metrics(env, act, s) for s in seeds]
    return {"eval_score": float(np.mean([m["reward_sum"] for m in ms])) / round(cfg.env.episode_s * 1000),
            "eval_v_target": float(np.mean([m["v_target"] for m in ms])),
            "eval_v_spill": float(np.mean([m["v_spill"] for m in ms])),
            "eval_finish_s": float(np.mean([m["finish_s"] for m in ms]))}


def _validation_callback(cfg: Any, run_dir: Path, episodes: int, every: int, seed: int, runner: Any,
                         quiet: bool, actor: str = "linear") -> Any:
    """Every `every` finished training episodes (and at the budget), the actor greedy on the validation
    seeds a pour-train run of cfg with this seed uses; each validation is a row of run_dir/log.csv (the
    trainer's columns) and an actor of checkpoint.npz's history, so that pour-results --reach reads the run as
    it reads the trainer's. The linear actor's W runs through the same C rollouts as the trainer's and its
    history is history_w (policy.json: the last and best validated W); the MLP's runs through the Gymnasium
    env, its history is history_mlp_<k> (layer k of every validation) and actor.json describes it. Stops the
    learning at the budget, and with an ExampleError when the actor stops being finite (the best validated
    one is kept)."""
    import time

    from stable_baselines3.common.callbacks import BaseCallback

    from pour.train import rundir

    valid_seeds = rundir.episode_seeds(seed, rundir.STREAM_VALID, 0, cfg.eval.episodes)
    config = cfg.to_dict()
    del config["workers"]
    keeps = "policy.json" if actor == "linear" else "checkpoint.npz"

    class Validation(BaseCallback):
        def _on_training_start(self) -> None:
            self.t0, self.done, self.due = time.monotonic(), 0, min(every, episodes)
            self.rows: list[dict[str, str]] = []
            self.history: list[Any] = []
            self.best, self.best_score = None, -np.inf
            self.bar = cli.bar(episodes, desc="PPO", quiet=quiet, unit="episode")

        def _on_step(self) -> bool:
            finished = int(np.sum(self.locals["dones"]))
            self.done += finished
            self.bar.update(finished)
            if self.done < self.due:
                return True
            snap = linear_weights(self.model) if actor == "linear" else mlp_layers(self.model)
            if not all(np.all(np.isfinite(a)) for a in (snap if actor == "mlp" else [snap])):
                raise ExampleError(f"PPO diverged after {self.done} episodes: the actor is not finite; "
                                   f"{run_dir / keeps} keeps the best validated weights")
            ev = rundir.greedy_validation(cfg, runner, snap, valid_seeds)[0] if actor == "linear" else \
                mlp_validation(cfg, snap, valid_seeds)
            if ev["eval_score"] > self.best_score or self.best is None:
                self.best, self.best_score = snap, float(ev["eval_score"])
            row = dict.fromkeys(rundir.LOG_FIELDS, np.nan)
            row.update(ev, iteration=len(self.rows), episodes=self.done, wall_s=time.monotonic() - self.t0,
                       best_score=self.best_score)
            self.rows.append({k: rundir.fmt(v) for k, v in row.items()})
            self.history.append(snap)
            rundir.write_log(run_dir / "log.csv", self.rows)
            fields = dict(learner="stable-baselines3 PPO", config=config, seed=int(seed), episodes=self.done,
                          ppo=dict(PPO_DEFAULTS), critic=list(CRITIC), best_score=self.best_score)
            state: dict[str, Any] = {"episodes": self.done, "wall_s": row["wall_s"]}
            if actor == "linear":
                export.write_policy(run_dir / "policy.json", cfg.policy.n_actions, cfg.policy.decision_period_ms,
                                    runner.tau_max_nm, episode.NORM, snap, self.best, **fields)
                state.update(history_w=np.array(self.history), best_w=self.best)
            else:
                write_actor(run_dir, cfg.policy.n_actions, cfg.policy.decision_period_ms, **fields)
                for k in range(len(snap)):
                    state[f"history_mlp_{k}"] = np.array([h[k] for h in self.history])
                    state[f"best_mlp_{k}"] = self.best[k]
            rundir.save_checkpoint(run_dir / "checkpoint.npz", state)
            self.due = min(self.due + every, episodes)
            return self.done < episodes

        def _on_training_end(self) -> None:
            self.bar.close()

    return Validation()


def write_actor(run_dir: Path, n_actions: int, decision_period_ms: int, **fields: Any) -> None:
    """run_dir/actor.json: what pour-results reads of an MLP run (its actor's layers are in checkpoint.npz)."""
    doc = {"format": "pour-mlp-actor/1", "actor": "mlp", "hidden": list(ACTORS["mlp"]), "activation": "tanh",
           "n_actions": int(n_actions), "decision_period_ms": int(decision_period_ms), **fields}
    atomic.write_atomic(run_dir / "actor.json", json.dumps(doc, indent=1) + "\n")


def train_run(config_path: str | Path, run_dir: str | Path, episodes: int, every: int, seed: int = 1,
              quiet: bool = True, actor: str = "linear", **ppo_kwargs: Any) -> Any:
    """PPO (actor 'linear': softmax-linear; 'mlp': SB3's MLP) on the rig, episode length and validation of a
    training config (its env and eval; not its method), for `episodes` training episodes, validated every
    `every`: a run directory pour-results --reach reads (log.csv, checkpoint.npz's actor history, and
    policy.json or actor.json). Returns the final actor: W [6][n_actions], or the MLP's layers."""
    from pour.train import config as cfgmod
    from pour.train import executors

    if episodes < 1 or not 1 <= every <= episodes:
        raise ExampleError(f"episodes = {episodes}, validate every {every}: expected 1 <= every <= episodes")
    if actor not in ACTORS:
        raise ExampleError(f"actor {actor!r}: expected one of {', '.join(ACTORS)}")
    cfg = cfgmod.load(config_path)
    if cfg.eval.episodes < 1:
        raise ExampleError(f"{config_path}: eval.episodes = 0: the run needs validation episodes")
    run_dir = _make_dir(run_dir)
    with executors.Runner(cfg) as runner:   # its workers fork before torch starts
        env = gym_env.PourEnv(cfg.env.kind, cfg.policy.n_actions, cfg.policy.decision_period_ms,
                              cfg.env.episode_s, cfg.env.options)
        model = make_model(env, seed, actor, **ppo_kwargs)
        cb = _validation_callback(cfg, run_dir, episodes, every, seed, runner, quiet, actor)
        # The callback stops the learning at the budget; the step count only has to be large enough.
        model.learn(total_timesteps=(episodes + 1) * env.max_decisions + model.n_steps, callback=cb)
        runner.close()
    model.save(run_dir / "sb3_model.zip")
    return linear_weights(model) if actor == "linear" else mlp_layers(model)


def _make_dir(path: str | Path) -> Path:
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ExampleError(f"{path}: cannot create ({exc.strerror})") from None
    return path


def write_run(run_dir: str | Path, model: Any, w: np.ndarray, steps: int, seed: int, env_id: str,
              **fields: Any) -> Path:
    """run_dir/policy.json (what pour-export reads; fields are recorded in it too) and run_dir/sb3_model.zip
    (SB3's own save)."""
    run_dir = _make_dir(run_dir)
    pe = model.get_env().envs[0].unwrapped
    if not isinstance(pe, gym_env.PourEnv):
        raise ExampleError(f"{env_id} is not a pour environment")
    path = run_dir / "policy.json"
    export.write_policy(path, pe.action_space.n, pe.period, pe.tau_max_nm, episode.NORM, w, w,
                        learner="stable-baselines3 PPO", env_id=env_id, steps=int(steps), seed=int(seed),
                        ppo=dict(PPO_DEFAULTS), critic=list(CRITIC), **fields)
    model.save(run_dir / "sb3_model.zip")
    return path


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="python -m pour.examples.sb3_ppo", description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=200_000, help="env steps (10 ms decisions) to train")
    ap.add_argument("--seed", type=int, default=1, help="PPO's and the env's seed")
    ap.add_argument("--env", default=ENV_ID, help=f"Gymnasium id (default {ENV_ID}; pour/PourRandomised-v0)")
    ap.add_argument("--init-header", type=Path, help="start the actor from this weights.h's W (e.g. policy/weights.h)")
    ap.add_argument("-o", "--out", required=True, type=Path, help="run directory: policy.json, sb3_model.zip")
    ap.add_argument("--header", type=Path, help="also export weights.h here (as pour-export RUN --out HEADER)")
    ap.add_argument("--like", metavar="CONFIG", type=Path,
                    help="train on this training config's rig, episode length and validation (e.g. "
                         "configs/train/ars11.toml) for --episodes episodes, logging as pour-train does, so "
                         "that pour-results --reach reads the run (instead of --steps and --env)")
    ap.add_argument("--episodes", type=int, default=960, help="--like: training episodes (the budget)")
    ap.add_argument("--validate-every", type=int, default=32, help="--like: training episodes between validations")
    ap.add_argument("--actor", choices=tuple(ACTORS), default="linear",
                    help="--like: the actor, softmax-linear (default; exports to weights.h) or SB3's MLP (two tanh "
                         "layers of 64; validated and evaluated through the Gymnasium env, no weights.h)")
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    try:
        _make_dir(args.out)
        if args.header is not None:
            atomic.check_output_path(args.header, "--header")
        if args.actor != "linear" and (args.like is None or args.header is not None):
            raise ExampleError(f"--actor {args.actor} needs --like, and has no W for --header")
        if args.like is not None:
            actor = train_run(args.like, args.out, args.episodes, args.validate_every, args.seed, args.quiet,
                              args.actor)
            if args.actor == "linear":
                path = args.out / "policy.json"
                print(f"{path}: W [6][{actor.shape[1]}] of PPO, {args.episodes} episodes like {args.like}, "
                      f"seed {args.seed}")
            else:
                print(f"{args.out / 'checkpoint.npz'}: the MLP actor of PPO, {args.episodes} episodes like "
                      f"{args.like}, seed {args.seed}")
        else:
            init_w = header_weights(args.init_header) if args.init_header is not None else None
            model, w = train(args.steps, args.seed, args.env, quiet=args.quiet, init_w=init_w)
            path = write_run(args.out, model, w, args.steps, args.seed, args.env,
                             init_header=None if args.init_header is None else str(args.init_header))
            print(f"{path}: W [6][{w.shape[1]}] of PPO, {args.steps} steps, seed {args.seed}")
        if args.header is not None:
            export.export(path, args.header)
            print(f"{args.header}: exported")
    except (ExampleError, export.ExportError, weights_h.WeightsHError, episode.EnvError, gym.error.Error,
            ValueError, OSError) as exc:
        print(f"sb3_ppo: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
