# SPDX-License-Identifier: MIT
"""Derivative-free search on greedy rollouts of the softmax-linear policy: augmented random search
(algo.kind = 'ars') and the cross-entropy method ('cem'), over the policy's parameters (W itself for
policy.param 'full', the six feedback gains beta for 'feedback').

ARS (Mania, Guy & Recht 2018, V1-t): each iteration draws `directions` Gaussian directions d_k, rolls out
theta + nu d_k and theta - nu d_k, keeps the `top` directions with the largest max(R+, R-) and steps

    theta <- theta + alpha / (top * sigma_R) * sum_k (R+_k - R-_k) d_k

where sigma_R is the standard deviation of the 2 * top returns kept. V2-t (ars.normalize_states) searches in
the coordinates of the standardised state (x_i - mu_i) / sigma_i, with mu and sigma the running mean and std
of every training rollout's features so far: a gain on a feature that moves little (the speed) is explored
as widely as one on a feature that sweeps [0, 1] (the angle), and a gain no longer drags the bias with it.
The policy it runs is still softmax(x W) on the raw features (state_coords folds mu and sigma into W).

CEM (Rubinstein; in control, e.g. Szita & Lorincz 2006): each iteration draws `population` candidates
from normal(mean, diag(std^2)), rolls them out, and refits mean and std to the `elites` best ones (std
floored at min_std). It compares candidates across the whole spread of the distribution instead of
differencing around one point, so it jumps between basins that a local estimate climbs out of slowly.

Both use common random numbers: every candidate of an iteration runs on the same episode seeds (rigs), so a
difference in return is the policy's and not the rig's. The draws come from (seed, STREAM_SEARCH,
iteration) through numpy's SeedSequence, so a run needs no RNG state to resume and is bit-identical
whatever the number of workers. The run directory is every method's (rundir.py): the same log, checkpoint
and policy.json, plus `history_w` (the centre's W after every iteration) in the checkpoint.

Divergence: parameters that are not finite, or a centre whose greedy validation score stays far below the
best one (eval.collapse, eval.collapse_patience), stop the run with TrainError; the checkpoint and
policy.json on disk still hold the best validated weights, which pour-export exports.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from pour.policy import weights_h
from pour.train import rundir
from pour.train.settings import TrainConfig


def draws(cfg: TrainConfig, it: int, n: int, shape: tuple) -> np.ndarray:
    """The iteration's standard normal draws, [n][*shape] (ARS's directions, CEM's candidates' noise)."""
    rng = np.random.default_rng(np.random.SeedSequence([cfg.seed, rundir.STREAM_SEARCH, it]))
    return rng.standard_normal((n, *shape))


def step_size(cfg: TrainConfig, it: int) -> float:
    return rundir.linear_schedule(cfg.ars.step_size, cfg.ars.step_size_final, it, cfg.iterations)


def noise(cfg: TrainConfig, it: int) -> float:
    return rundir.geometric_schedule(cfg.ars.noise, cfg.ars.noise_final, it, cfg.iterations)


class StateStats:
    """The running mean and variance of the five state features (not the bias) over every decision row seen."""

    def __init__(self, n: float = 0.0, mean: np.ndarray | None = None, m2: np.ndarray | None = None):
        self.n, self.mean = n, np.zeros(5) if mean is None else np.array(mean, dtype=np.float64)
        self.m2 = np.zeros(5) if m2 is None else np.array(m2, dtype=np.float64)

    def add(self, x: np.ndarray) -> None:
        """Merges the rows of x [T][6] (Chan et al.'s pairwise update: exact, order-independent to rounding)."""
        x = np.asarray(x, dtype=np.float64)[:, :5]
        nb = float(len(x))
        if nb == 0:
            return
        mb, m2b = x.mean(axis=0), ((x - x.mean(axis=0)) ** 2).sum(axis=0)
        n = self.n + nb
        d = mb - self.mean
        self.mean = self.mean + d * nb / n
        self.m2 = self.m2 + m2b + d ** 2 * self.n * nb / n
        self.n = n

    def std(self, floor: float) -> np.ndarray:
        """The std of each feature, floored; 1 (the raw coordinates) before any row was seen."""
        if self.n < 2:
            return np.ones(5)
        return np.maximum(np.sqrt(self.m2 / self.n), floor)


def state_coords(p: np.ndarray, mean: np.ndarray, std: np.ndarray) -> np.ndarray:
    """The raw-feature parameters (rows: theta, omega, V_rot, V_tgt, V_spill, bias) equivalent to parameters p
    over the standardised features: p_i / std_i, and the bias less sum_i p_i mean_i / std_i."""
    scale = (1.0 / std).reshape((5,) + (1,) * (p.ndim - 1))
    raw = np.array(p, dtype=np.float64)
    raw[:5] = p[:5] * scale
    raw[5] = p[5] - np.tensordot(mean, raw[:5], axes=1)
    return raw


def ars_step(deltas: np.ndarray, r_plus: np.ndarray, r_minus: np.ndarray, top: int, alpha: float
             ) -> tuple[np.ndarray, float]:
    """The increment of one iteration and sigma_R. r_plus, r_minus: each direction's mean return on its
    episodes. sigma_R below 1e-12 (every kept return equal: no information) gives no step."""
    order = np.argsort(-np.maximum(r_plus, r_minus), kind="stable")[:top]
    kept = np.concatenate([r_plus[order], r_minus[order]])
    sigma = float(np.std(kept))
    if not sigma > 1e-12:
        return np.zeros(deltas.shape[1:]), sigma
    diff = (r_plus[order] - r_minus[order]).reshape((-1,) + (1,) * (deltas.ndim - 1))
    return alpha / (top * sigma) * np.sum(diff * deltas[order], axis=0), sigma


def cem_update(cands: np.ndarray, returns: np.ndarray, elites: int, min_std: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """The next (mean, std): those of the `elites` candidates with the highest returns (ties: lowest index)."""
    best = cands[np.argsort(-returns, kind="stable")[:elites]]
    return best.mean(axis=0), np.maximum(best.std(axis=0), min_std)


def train(cfg: TrainConfig, run_dir: Path, resume: bool, quiet: bool, stop_after: int | None,
          make_runner: Any) -> rundir.RunResult:
    """trainer.train for algo.kind 'ars' and 'cem' (pour.train.methods)."""
    run = rundir.Run(cfg, run_dir)
    r = cfg.ars
    gamma_d = cfg.algo.gamma ** cfg.policy.decision_period_ms
    params = rundir.initial_params(cfg)
    std = np.full(params.shape, cfg.cem.init_std)   # CEM's spread (unused by ARS)
    stats = StateStats()                            # V2-t's state statistics (ars.normalize_states)
    names = r.features or list(weights_h.FEATURE_NAMES)  # the rows ARS moves (ars.features)
    searched = np.array([f in names for f in weights_h.FEATURE_NAMES], dtype=np.float64).reshape(
        (6,) + (1,) * (params.ndim - 1))

    def to_w(p: np.ndarray) -> np.ndarray:
        if cfg.algo.kind == "ars" and r.normalize_states:
            p = state_coords(p, stats.mean, stats.std(r.state_std_min))
        return rundir.weights(cfg, p)

    w = to_w(params)
    best_w, best_score, start, wall_prev = w.copy(), -np.inf, 0, 0.0
    best_ep: dict[str, np.ndarray] = {}
    history: list[np.ndarray] = []
    n_low = 0  # evaluations in a row far below the best (eval.collapse)
    st, rows = run.open(resume, quiet, lambda s: "history_w" in s,
                        f", algo.kind = {cfg.algo.kind!r} needs its own state")
    if st is not None:
        params, best_w, best_score = np.array(st["params"]), np.array(st["best_w"]), float(st["best_score"])
        stats = StateStats(float(st.get("state_n", 0.0)), st.get("state_mean"), st.get("state_m2"))
        w = to_w(params)
        start, wall_prev, n_low = int(st["iteration"]), float(st["wall_s"]), int(st["n_low"])
        history = list(np.array(st["history_w"]))
        std = np.array(st["cem_std"])
        best_ep = {k: st[k] for k in st if k.startswith("best_ep_")}

    valid_seeds = rundir.episode_seeds(cfg.seed, rundir.STREAM_VALID, 0, cfg.eval.episodes)
    is_ars, c, v = cfg.algo.kind == "ars", cfg.cem, cfg.eval
    per_iteration = 2 * r.directions * r.episodes_per_direction if is_ars else c.population * c.episodes_per_candidate
    t0 = time.monotonic()
    with make_runner(cfg) as runner:
        for it in rundir.iterations(cfg, start, stop_after):
            m = r.episodes_per_direction if is_ars else c.episodes_per_candidate
            seeds = rundir.episode_seeds(cfg.seed, rundir.STREAM_TRAIN, it, m)
            if is_ars:
                deltas = draws(cfg, it, r.directions, params.shape) * searched
                nu = noise(cfg, it)
                cands = np.stack([params + sign * nu * d for d in deltas for sign in (1.0, -1.0)])
            else:
                cands = params + std * draws(cfg, it, c.population, params.shape)
            ws = [to_w(p) for p in cands]
            eps = runner.run_each([wk for wk in ws for _ in seeds], seeds * len(ws), greedy=True)
            rets = np.array([rundir.episode_return(e, gamma_d) for e in eps]) * cfg.algo.reward_scale
            per_cand = rets.reshape(len(ws), m).mean(axis=1)
            alpha, sigma = step_size(cfg, it), float(np.std(per_cand))
            with np.errstate(over="ignore", invalid="ignore"):
                if is_ars:
                    by_side = per_cand.reshape(r.directions, 2)
                    step, sigma = ars_step(deltas, by_side[:, 0], by_side[:, 1], r.top, alpha)
                    new_params = params + step
                else:
                    new_params, std = cem_update(cands, per_cand, c.elites, c.min_std)
                    step = new_params - params
            if not (np.all(np.isfinite(new_params)) and np.all(np.isfinite(std))):
                raise rundir.TrainError(
                    f"{run_dir}: iteration {it}: the parameters diverged (non-finite after a step, sigma_R "
                    f"{sigma:g}); stopped. The best validated weights (score {best_score:.6g}) "
                    "are kept in checkpoint.npz and policy.json: pour-export exports them; lower ars.step_size")
            params = new_params
            for e in eps:
                stats.add(e.x)
            w = to_w(params)
            history.append(w.copy())
            best_ep = rundir.best_episode(best_ep, eps, rets, it)
            ev, se = rundir.validate(cfg, runner, w, valid_seeds, it)
            collapsed = ""
            if np.isfinite(ev["eval_score"]):
                sc = ev["eval_score"]
                if v.collapse > 0 and np.isfinite(best_score) and sc < best_score - v.collapse * abs(best_score) - se:
                    n_low += 1
                    if n_low >= v.collapse_patience:
                        collapsed = (f"{run_dir}: iteration {it}: the return collapsed (validation score {sc:.6g}, "
                                     f"best {best_score:.6g}, {n_low} evaluations in a row more than "
                                     f"{v.collapse:g} x |best| below it); stopped. The best validated weights "
                                     "are kept in checkpoint.npz and policy.json: pour-export exports them")
                else:
                    n_low = 0
                if sc > best_score or not cfg.eval.select_best:
                    best_score, best_w = sc, w.copy()
            wall = wall_prev + time.monotonic() - t0
            row = {"iteration": it, "episodes": (it + 1) * per_iteration, "wall_s": wall,
                   **rundir.batch_columns(rets, eps), "entropy_mean": np.nan, "grad_norm": float(np.linalg.norm(step)), "lr": alpha,
                   "kl_bound": np.nan, "kl": np.nan, "step_scale": 1.0, "rolled_back": 0, **ev,
                   "best_score": best_score}
            rows.append({k: rundir.fmt(v) for k, v in row.items()})
            run.save(rows, runner.tau_max_nm,
                     {"params": params, "w": w, "best_w": best_w, "best_score": best_score, "iteration": it + 1,
                      "wall_s": wall, "config_digest": run.digest, "history_w": np.array(history), "n_low": n_low,
                      "cem_std": std, "state_n": stats.n, "state_mean": stats.mean, "state_m2": stats.m2,
                      **best_ep})
            if not quiet:
                print(f"[pour-train] it {it + 1}/{cfg.iterations} R {rets.mean():9.3f} ±{rets.std():7.3f} "
                      f"tgt {row['v_target_mean']:.3f} spill {row['v_spill_mean']:.3f} |step| {row['grad_norm']:.4f} "
                      f"eval {ev['eval_score']:.4f} best {best_score:.4f} [{wall:6.1f} s]", file=sys.stderr, flush=True)
            if collapsed:
                raise rundir.TrainError(collapsed)
        runner.close()
    return run.result(w, best_w, best_score, start, wall_prev)

