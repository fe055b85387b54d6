# SPDX-License-Identifier: MIT
"""The policy-gradient methods (algo.kind 'vanilla', the seed paper's update, and 'pg', the improved one):
batches of stochastic rollouts, one REINFORCE step each (reinforce.py's maths), optionally in a trust
region and with rollback. The run directory is rundir.py's.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import cli
from pour.policy import linear
from pour.sim import envs
from pour.train import reinforce, rundir
from pour.train.settings import TrainConfig


def _entropy_coef(cfg: TrainConfig, it: int) -> float:
    a = cfg.algo
    frac = it / max(1, cfg.iterations - 1)
    return a.entropy_coef + (a.entropy_coef_final - a.entropy_coef) * frac


def learning_rate(cfg: TrainConfig, it: int) -> float:
    return rundir.linear_schedule(cfg.algo.lr, cfg.algo.lr_final, it, cfg.iterations)


def max_kl(cfg: TrainConfig, it: int) -> float:
    """The trust region's bound at iteration it [nats]: max_kl, decayed geometrically to max_kl_final."""
    return rundir.geometric_schedule(cfg.algo.max_kl, cfg.algo.max_kl_final, it, cfg.iterations)


def update(cfg: TrainConfig, w: np.ndarray, eps: Sequence[envs.Episode], opt: reinforce.Adam | None,
           it: int, kl_bound: float | None = None) -> tuple[np.ndarray, dict[str, float]]:
    """One policy-gradient step on a batch of episodes; returns (new parameters, step statistics).

    w is the parameter vector (for policy.param 'full' it is W itself). The statistics: grad_norm
    (before clipping), lr, kl (mean KL(old || new) over the batch's states [nats]) and step_scale
    (the trust region's backtracking factor, 1 when the step was taken whole)."""
    with np.errstate(over="ignore", invalid="ignore"):  # non-finite results are caught below, by name
        return _update(cfg, w, eps, opt, it, max_kl(cfg, it) if kl_bound is None else kl_bound)


def _update(cfg: TrainConfig, w: np.ndarray, eps: Sequence[envs.Episode], opt: reinforce.Adam | None,
            it: int, delta: float) -> tuple[np.ndarray, dict[str, float]]:
    a = cfg.algo
    gamma_d = a.gamma ** cfg.policy.decision_period_ms
    batch = reinforce.Batch(np.stack([e.x for e in eps]), np.stack([e.actions for e in eps]),
                            np.stack([e.rewards for e in eps]) * a.reward_scale)
    adv = reinforce.advantages(batch, gamma_d, a.reward_to_go, a.baseline, a.normalize_advantages)
    g_w = reinforce.batch_gradient(rundir.weights(cfg, w), batch, adv, _entropy_coef(cfg, it))
    g = reinforce.grad_params(cfg.policy.param, g_w, cfg.policy.n_actions, cfg.policy.sharpness)
    reinforce.check_finite("gradient", g, it)
    g, norm = reinforce.clip_norm(g, a.grad_clip)
    lr = learning_rate(cfg, it)
    w_old = rundir.weights(cfg, w)
    x = batch.x.reshape(-1, batch.x.shape[-1])
    if a.optimizer == "natural":
        step = reinforce.natural_step(g, reinforce.fisher(cfg.policy.param, w_old, x, cfg.policy.sharpness), delta)
    elif opt is not None:
        opt.lr = lr
        step = opt.step(g)
    else:
        step = lr * g

    def kl_of(s: np.ndarray) -> float:
        return reinforce.mean_kl(w_old, rundir.weights(cfg, w + s), x)

    if delta > 0:
        step, kl, scale = reinforce.trust_region(step, kl_of, delta)
    else:
        kl, scale = kl_of(step), 1.0
    w_new = w + step
    reinforce.check_finite("weights", w_new, it)
    return w_new, {"grad_norm": norm, "lr": lr, "kl_bound": delta, "kl": kl, "step_scale": scale}


def train(cfg: TrainConfig, run_dir: Path, resume: bool, quiet: bool, stop_after: int | None,
          make_runner: Any) -> rundir.RunResult:
    """trainer.train for algo.kind 'vanilla' and 'pg' (pour.train.methods)."""
    run = rundir.Run(cfg, run_dir)
    params = rundir.initial_params(cfg)
    w = rundir.weights(cfg, params)
    best_w, best_score, start, wall_prev = w.copy(), -np.inf, 0, 0.0
    opt = reinforce.Adam(params.shape, cfg.algo.lr) if cfg.algo.optimizer == "adam" else None
    best_ep: dict[str, np.ndarray] = {}
    history: list[np.ndarray] = []  # W after every iteration (pour-results' episodes to reach the bars)
    # Rollback (algo.rollback > 0): the parameters of the best batch so far, its mean return and its
    # standard error, and how many steps were undone (each one shrinks the trust region).
    anchor_params, anchor_ret, anchor_se, n_rollbacks = params.copy(), -np.inf, 0.0, 0
    st, rows = run.open(resume, quiet)
    if st is not None:
        params, best_w, best_score = st["params"], st["best_w"], float(st["best_score"])
        w = rundir.weights(cfg, params)
        start, wall_prev = int(st["iteration"]), float(st["wall_s"])
        if opt is not None:
            opt.load_state_dict(st)
        best_ep = {k: st[k] for k in st if k.startswith("best_ep_")}
        history = list(np.array(st["history_w"])) if "history_w" in st else []
        if "anchor_params" in st:
            anchor_params, anchor_ret = np.array(st["anchor_params"]), float(st["anchor_ret"])
            anchor_se, n_rollbacks = float(st["anchor_se"]), int(st["n_rollbacks"])

    gamma_d = cfg.algo.gamma ** cfg.policy.decision_period_ms
    valid_seeds = rundir.episode_seeds(cfg.seed, rundir.STREAM_VALID, 0, cfg.eval.episodes)
    t0 = time.monotonic()
    with make_runner(cfg) as runner:
        for it in rundir.iterations(cfg, start, stop_after):
            seeds = rundir.episode_seeds(cfg.seed, rundir.STREAM_TRAIN, it, cfg.algo.batch_episodes)
            eps = runner.run(w, seeds, greedy=False)
            rets = np.array([rundir.episode_return(e, gamma_d) for e in eps])
            ent = float(np.mean([np.mean(reinforce.entropy(linear.probs(w, e.x))) for e in eps]))
            best_ep = rundir.best_episode(best_ep, eps, rets, it)
            rolled = 0
            if cfg.algo.rollback > 0:
                r_mean = float(rets.mean())
                if it >= cfg.algo.rollback_from and \
                        r_mean < anchor_ret - cfg.algo.rollback * abs(anchor_ret) - 2.0 * anchor_se:
                    rolled = 1
                elif r_mean > anchor_ret:
                    anchor_params, anchor_ret = params.copy(), r_mean
                    anchor_se = float(rets.std()) / np.sqrt(len(rets))
            bound = max_kl(cfg, it) * cfg.algo.rollback_shrink ** n_rollbacks
            if rolled:
                # The last step made the batch return drop by more than the tolerance: undo it, forget
                # Adam's momentum (it points over the same edge) and shrink the trust region.
                n_rollbacks += 1
                params = anchor_params.copy()
                if opt is not None:
                    opt.m[...] = 0.0
                stats = {"grad_norm": np.nan, "lr": learning_rate(cfg, it), "kl_bound": bound, "kl": 0.0,
                         "step_scale": 0.0}
            else:
                params, stats = update(cfg, params, eps, opt, it, bound)
            w = rundir.weights(cfg, params)
            history.append(w.copy())
            ev, _ = rundir.validate(cfg, runner, w, valid_seeds, it)
            if np.isfinite(ev["eval_score"]):
                sc = ev["eval_score"]
                if sc > best_score or not cfg.eval.select_best:
                    best_score, best_w = sc, w.copy()
            wall = wall_prev + time.monotonic() - t0
            row = {"iteration": it, "episodes": (it + 1) * cfg.algo.batch_episodes, "wall_s": wall,
                   **rundir.batch_columns(rets, eps), "entropy_mean": ent, **stats, "rolled_back": rolled, **ev,
                   "best_score": best_score}
            rows.append({k: rundir.fmt(v) for k, v in row.items()})
            run.save(rows, runner.tau_max_nm,
                     {"params": params, "w": w, "best_w": best_w, "best_score": best_score, "iteration": it + 1,
                      "wall_s": wall, "config_digest": run.digest, **(opt.state_dict() if opt is not None else {}),
                      **best_ep, "anchor_params": anchor_params, "anchor_ret": anchor_ret, "anchor_se": anchor_se,
                      "n_rollbacks": n_rollbacks, "history_w": np.array(history)})
            if not quiet:
                print(f"[pour-train] it {it + 1}/{cfg.iterations} R {rets.mean():9.3f} ±{rets.std():7.3f} "
                      f"tgt {row['v_target_mean']:.3f} spill {row['v_spill_mean']:.3f} H {ent:.2f} "
                      f"KL {stats['kl']:.4f} eval {ev['eval_score']:.4f} best {best_score:.4f} [{wall:6.1f} s, "
                      f"{cli.time_left(it + 1 - start, cfg.iterations - start, time.monotonic() - t0)} left]",
                      file=sys.stderr, flush=True)
        runner.close()
    return run.result(w, best_w, best_score, start, wall_prev)
