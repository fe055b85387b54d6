# SPDX-License-Identifier: MIT
"""pour-train: REINFORCE on the softmax-linear pour policy, rollouts in C on every core.

A run lives in one directory: config.json (the config it was started with), log.csv (one row per
iteration) and checkpoint.npz (weights, optimiser state, best weights), each written atomically
(temporary file, then rename), so a killed run resumes with no finished iteration lost and ends
bit-identical to an uninterrupted one. Episode seeds derive from (config seed, stream, iteration),
never from the worker that runs them, so the number of workers does not change the result.
"""
from __future__ import annotations

import csv
import dataclasses
import importlib
import io
import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from pour import cli
from pour.policy import export, linear
from pour.sim import envs
from pour.sysid import rig as srig
from pour.train import config as cfgmod
from pour.train import executors, reinforce
from pour.train.executors import Runner  # the local pool, the default executor (also as trainer.Runner)

STREAM_TRAIN, STREAM_VALID, STREAM_TEST = 0, 1, 2
STREAM_INIT = 4  # policy.init = "random" (ars.py's draws are stream 3)

LOG_FIELDS = ["iteration", "episodes", "wall_s", "return_mean", "return_std", "return_min", "return_max",
              "reward_sum_mean", "v_target_mean", "v_spill_mean", "finish_s_mean", "entropy_mean",
              "grad_norm", "lr", "kl_bound", "kl", "step_scale", "rolled_back", "eval_score", "eval_v_target", "eval_v_spill", "eval_finish_s", "best_score"]


class TrainError(RuntimeError):
    """A run that cannot start or continue (bad run directory, config mismatch)."""


def episode_seeds(seed: int, stream: int, index: int, n: int) -> list[int]:
    """n episode seeds (uint32) for one iteration (or evaluation set) of one stream."""
    ss = np.random.SeedSequence([seed, stream, index])
    return [int(s) for s in ss.generate_state(n, dtype=np.uint32)]


# --- atomic files ---------------------------------------------------------------------------------

def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Writes data to path so that a reader (or a crash) sees the old or the new file, never half."""
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def save_checkpoint(path: Path, state: dict[str, Any]) -> None:
    buf = io.BytesIO()
    np.savez(buf, **{k: np.asarray(v) for k, v in state.items()})
    atomic_write_bytes(path, buf.getvalue())


def load_checkpoint(path: Path) -> dict[str, Any]:
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, KeyError) as exc:
        raise TrainError(f"{path}: not a readable checkpoint ({exc})") from exc


def read_log(path: Path) -> list[dict[str, str]]:
    if not path.exists():
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def write_log(path: Path, rows: list[dict[str, Any]]) -> None:
    buf = io.StringIO()
    wr = csv.DictWriter(buf, fieldnames=LOG_FIELDS, lineterminator="\n")
    wr.writeheader()
    for r in rows:
        wr.writerow({k: r[k] for k in LOG_FIELDS})
    atomic_write_bytes(path, buf.getvalue().encode())


def _fmt(v: Any) -> str:
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, str):
        return v
    return f"{float(v):.9g}"


# --- the training loop ------------------------------------------------------------------------------

@dataclass
class RunResult:
    run_dir: Path
    w: np.ndarray
    best_w: np.ndarray
    best_score: float
    iterations: int
    wall_s: float


def write_policy_json(path: Path, cfg: cfgmod.TrainConfig, tau_max_nm: float, iteration: int, w: np.ndarray,
                      best_w: np.ndarray, best_score: float) -> None:
    """The exporter's input: deterministic bytes (no times, and not `workers`, which changes the speed
    and nothing else), so a re-run exports the same weights.h whatever its worker count."""
    config = cfg.to_dict()
    del config["workers"]
    export.write_policy(path, cfg.policy.n_actions, cfg.policy.decision_period_ms, tau_max_nm, envs.NORM, w, best_w,
                        config=config, config_digest=cfg.digest(), iteration=iteration, best_score=best_score)


def episode_return(ep: envs.Episode, gamma_decision: float) -> float:
    return reinforce.discounted_return(ep.rewards, gamma_decision)


def initial_params(cfg: cfgmod.TrainConfig) -> np.ndarray:
    """The run's starting parameters: zeros, policy.init_beta, or seeded normal(0, init_scale^2)."""
    shape = reinforce.params_shape(cfg.policy.param, cfg.policy.n_actions)
    if cfg.policy.init == "beta":
        return np.array(cfg.policy.init_beta, dtype=np.float64)
    if cfg.policy.init == "random":
        rng = np.random.default_rng(np.random.SeedSequence([cfg.seed, STREAM_INIT]))
        return cfg.policy.init_scale * rng.standard_normal(shape)
    return np.zeros(shape)


def score(episodes: Sequence[envs.Episode], steps: int) -> float:
    """Validation score: the per-tick reward averaged over the episode and over the episodes."""
    return float(np.mean([np.sum(e.rewards) for e in episodes])) / steps


def _entropy_coef(cfg: cfgmod.TrainConfig, it: int) -> float:
    a = cfg.algo
    frac = it / max(1, cfg.iterations - 1)
    return a.entropy_coef + (a.entropy_coef_final - a.entropy_coef) * frac


def weights(cfg: cfgmod.TrainConfig, params: np.ndarray) -> np.ndarray:
    """The policy's W for the run's parameter vector."""
    return reinforce.w_from_params(cfg.policy.param, params, cfg.policy.n_actions, cfg.policy.sharpness)


def linear_schedule(start: float, final: float, it: int, iterations: int) -> float:
    """start at iteration 0, linearly to final at the last iteration; final < 0: constant start."""
    if final < 0:
        return start
    return start + (final - start) * it / max(1, iterations - 1)


def geometric_schedule(start: float, final: float, it: int, iterations: int) -> float:
    """start at iteration 0, geometrically to final at the last iteration; final < 0 or start 0: constant."""
    if final < 0 or start == 0:
        return start
    return start * (final / start) ** (it / max(1, iterations - 1))


def learning_rate(cfg: cfgmod.TrainConfig, it: int) -> float:
    return linear_schedule(cfg.algo.lr, cfg.algo.lr_final, it, cfg.iterations)


def max_kl(cfg: cfgmod.TrainConfig, it: int) -> float:
    """The trust region's bound at iteration it [nats]: max_kl, decayed geometrically to max_kl_final."""
    return geometric_schedule(cfg.algo.max_kl, cfg.algo.max_kl_final, it, cfg.iterations)


def update(cfg: cfgmod.TrainConfig, w: np.ndarray, eps: Sequence[envs.Episode], opt: reinforce.Adam | None,
           it: int, kl_bound: float | None = None) -> tuple[np.ndarray, dict[str, float]]:
    """One policy-gradient step on a batch of episodes; returns (new parameters, step statistics).

    w is the parameter vector (for policy.param 'full' it is W itself). The statistics: grad_norm
    (before clipping), lr, kl (mean KL(old || new) over the batch's states [nats]) and step_scale
    (the trust region's backtracking factor, 1 when the step was taken whole)."""
    with np.errstate(over="ignore", invalid="ignore"):  # non-finite results are caught below, by name
        return _update(cfg, w, eps, opt, it, max_kl(cfg, it) if kl_bound is None else kl_bound)


def _update(cfg: cfgmod.TrainConfig, w: np.ndarray, eps: Sequence[envs.Episode], opt: reinforce.Adam | None,
            it: int, delta: float) -> tuple[np.ndarray, dict[str, float]]:
    a = cfg.algo
    gamma_d = a.gamma ** cfg.policy.decision_period_ms
    batch = reinforce.Batch(np.stack([e.x for e in eps]), np.stack([e.actions for e in eps]),
                            np.stack([e.rewards for e in eps]) * a.reward_scale)
    adv = reinforce.advantages(batch, gamma_d, a.reward_to_go, a.baseline, a.normalize_advantages)
    g_w = reinforce.batch_gradient(weights(cfg, w), batch, adv, _entropy_coef(cfg, it))
    g = reinforce.grad_params(cfg.policy.param, g_w, cfg.policy.n_actions, cfg.policy.sharpness)
    reinforce.check_finite("gradient", g, it)
    g, norm = reinforce.clip_norm(g, a.grad_clip)
    lr = learning_rate(cfg, it)
    w_old = weights(cfg, w)
    x = batch.x.reshape(-1, batch.x.shape[-1])
    if a.optimizer == "natural":
        step = reinforce.natural_step(g, reinforce.fisher(cfg.policy.param, w_old, x, cfg.policy.sharpness), delta)
    elif opt is not None:
        opt.lr = lr
        step = opt.step(g)
    else:
        step = lr * g

    def kl_of(s: np.ndarray) -> float:
        return reinforce.mean_kl(w_old, weights(cfg, w + s), x)

    if delta > 0:
        step, kl, scale = reinforce.trust_region(step, kl_of, delta)
    else:
        kl, scale = kl_of(step), 1.0
    w_new = w + step
    reinforce.check_finite("weights", w_new, it)
    return w_new, {"grad_norm": norm, "lr": lr, "kl_bound": delta, "kl": kl, "step_scale": scale}


def iterations(cfg: cfgmod.TrainConfig, start: int, stop_after: int | None) -> range:
    """The iterations one call runs: from start to the config's end, at most stop_after of them."""
    end = cfg.iterations if stop_after is None else min(cfg.iterations, start + stop_after)
    return range(start, end)


def validate(cfg: cfgmod.TrainConfig, runner: Any, w: np.ndarray, seeds: Sequence[int], it: int
             ) -> tuple[dict[str, float], float]:
    """The greedy validation of W when iteration it is due one (every eval.every and the last): the log's
    eval_* columns (NaN when not due) and the score's standard error."""
    if not cfg.eval.episodes or ((it + 1) % cfg.eval.every != 0 and it != cfg.iterations - 1):
        return dict.fromkeys(("eval_score", "eval_v_target", "eval_v_spill", "eval_finish_s"), np.nan), np.nan
    return greedy_validation(cfg, runner, w, seeds)


def greedy_validation(cfg: cfgmod.TrainConfig, runner: Any, w: np.ndarray, seeds: Sequence[int]
                      ) -> tuple[dict[str, float], float]:
    """W greedy on the validation seeds, now: the log's eval_* columns and the score's standard error (also
    for other learners' run directories, pour.examples.sb3_ppo)."""
    steps = int(round(cfg.env.episode_s * 1000))
    veps = runner.run(w, seeds, greedy=True)
    ev = {"eval_score": score(veps, steps),
          "eval_v_target": np.mean([e.metrics["v_target"] for e in veps]),
          "eval_v_spill": np.mean([e.metrics["v_spill"] for e in veps]),
          "eval_finish_s": np.mean([e.metrics["finish_s"] for e in veps])}
    return ev, float(np.std([np.sum(e.rewards) for e in veps])) / steps / np.sqrt(len(veps))


# algo.kind -> its train(cfg, run_dir, resume, quiet, stop_after, make_runner); pour.train.ars registers
# 'ars' and 'cem' when it is imported, which train() does by name for those kinds (ars builds on this module).
SEARCH_METHODS: dict[str, Any] = {}
SEARCH_MODULE = "pour.train.ars"


def train(cfg: cfgmod.TrainConfig, run_dir: str | Path, resume: bool = True, quiet: bool = False,
          stop_after: int | None = None, make_runner: Any = Runner) -> RunResult:
    """Trains (or resumes) a run in run_dir. stop_after: return after that many iterations this call.
    make_runner: cfg -> the episode runner (Runner, the local pool, or executors.RayRunner): same results."""
    run_dir = Path(run_dir)
    if cfg.algo.kind in ("ars", "cem"):
        importlib.import_module(SEARCH_MODULE)  # the search methods build on this module's run directory
        return SEARCH_METHODS[cfg.algo.kind](cfg, run_dir, resume, quiet, stop_after, make_runner)
    run_dir.mkdir(parents=True, exist_ok=True)
    ckpt_path, log_path, cfg_path = run_dir / "checkpoint.npz", run_dir / "log.csv", run_dir / "config.json"
    digest = cfg.digest()

    params = initial_params(cfg)
    w = weights(cfg, params)
    best_w, best_score, start, wall_prev = w.copy(), -np.inf, 0, 0.0
    opt = reinforce.Adam(params.shape, cfg.algo.lr) if cfg.algo.optimizer == "adam" else None
    best_ep: dict[str, np.ndarray] = {}
    history: list[np.ndarray] = []  # W after every iteration (pour-results' episodes to reach the bars)
    rows: list[dict[str, Any]] = []
    # Rollback (algo.rollback > 0): the parameters of the best batch so far, its mean return and its
    # standard error, and how many steps were undone (each one shrinks the trust region).
    anchor_params, anchor_ret, anchor_se, n_rollbacks = params.copy(), -np.inf, 0.0, 0
    if ckpt_path.exists() and resume:
        st = load_checkpoint(ckpt_path)
        if str(st["config_digest"]) != digest:
            raise TrainError(f"{run_dir}: checkpoint was made with a different config "
                             f"(digest {str(st['config_digest'])[:12]} vs {digest[:12]}); "
                             "use a new run directory or --fresh")
        params, best_w, best_score = st["params"], st["best_w"], float(st["best_score"])
        w = weights(cfg, params)
        start, wall_prev = int(st["iteration"]), float(st["wall_s"])
        if opt is not None:
            opt.load_state_dict(st)
        best_ep = {k: st[k] for k in st if k.startswith("best_ep_")}
        history = list(np.array(st["history_w"])) if "history_w" in st else []
        if "anchor_params" in st:
            anchor_params, anchor_ret = np.array(st["anchor_params"]), float(st["anchor_ret"])
            anchor_se, n_rollbacks = float(st["anchor_se"]), int(st["n_rollbacks"])
        rows = [r for r in read_log(log_path) if int(r["iteration"]) < start]
        if not quiet:
            print(f"[pour-train] resuming {run_dir} at iteration {start}", file=sys.stderr)
    elif ckpt_path.exists() or log_path.exists():
        for p in (ckpt_path, log_path):
            if p.exists():
                p.unlink()
    atomic_write_bytes(cfg_path, (json.dumps(cfg.to_dict(), indent=2, sort_keys=True) + "\n").encode())
    write_log(log_path, rows)

    gamma_d = cfg.algo.gamma ** cfg.policy.decision_period_ms
    valid_seeds = episode_seeds(cfg.seed, STREAM_VALID, 0, cfg.eval.episodes)
    t0 = time.monotonic()
    with make_runner(cfg) as runner:
        for it in iterations(cfg, start, stop_after):
            eps = runner.run(w, episode_seeds(cfg.seed, STREAM_TRAIN, it, cfg.algo.batch_episodes), greedy=False)
            rets = np.array([episode_return(e, gamma_d) for e in eps])
            ent = float(np.mean([np.mean(reinforce.entropy(linear.probs(w, e.x))) for e in eps]))
            ib = int(np.argmax(rets))
            if not best_ep or rets[ib] > float(best_ep["best_ep_return"]):
                e = eps[ib]
                best_ep = {"best_ep_x": e.x, "best_ep_actions": e.actions, "best_ep_rewards": e.rewards,
                           "best_ep_return": np.array(rets[ib]), "best_ep_iteration": np.array(it)}
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
            w = weights(cfg, params)
            history.append(w.copy())
            ev, _ = validate(cfg, runner, w, valid_seeds, it)
            if np.isfinite(ev["eval_score"]):
                sc = ev["eval_score"]
                if sc > best_score or not cfg.eval.select_best:
                    best_score, best_w = sc, w.copy()
            wall = wall_prev + time.monotonic() - t0
            row = {"iteration": it, "episodes": (it + 1) * cfg.algo.batch_episodes, "wall_s": wall,
                   "return_mean": rets.mean(), "return_std": rets.std(), "return_min": rets.min(),
                   "return_max": rets.max(),
                   "reward_sum_mean": np.mean([np.sum(e.rewards) for e in eps]),
                   "v_target_mean": np.mean([e.metrics["v_target"] for e in eps]),
                   "v_spill_mean": np.mean([e.metrics["v_spill"] for e in eps]),
                   "finish_s_mean": np.mean([e.metrics["finish_s"] for e in eps]),
                   "entropy_mean": ent, **stats, "rolled_back": rolled, **ev, "best_score": best_score}
            rows.append({k: _fmt(v) for k, v in row.items()})
            state = {"params": params, "w": w, "best_w": best_w, "best_score": best_score, "iteration": it + 1, "wall_s": wall,
                     "config_digest": digest, **(opt.state_dict() if opt is not None else {}), **best_ep,
                     "anchor_params": anchor_params, "anchor_ret": anchor_ret, "anchor_se": anchor_se,
                     "n_rollbacks": n_rollbacks, "history_w": np.array(history)}
            # Log first, then the checkpoint: a crash in between leaves a log row the resume drops.
            write_log(log_path, rows)
            write_policy_json(run_dir / "policy.json", cfg, runner.tau_max_nm, it + 1, w, best_w, best_score)
            save_checkpoint(ckpt_path, state)
            if not quiet:
                print(f"[pour-train] it {it + 1}/{cfg.iterations} R {rets.mean():9.3f} ±{rets.std():7.3f} "
                      f"tgt {row['v_target_mean']:.3f} spill {row['v_spill_mean']:.3f} H {ent:.2f} "
                      f"KL {stats['kl']:.4f} eval {ev['eval_score']:.4f} best {best_score:.4f} [{wall:6.1f} s, "
                      f"{cli.time_left(it + 1 - start, cfg.iterations - start, time.monotonic() - t0)} left]",
                      file=sys.stderr, flush=True)
        runner.close()
    final = load_checkpoint(ckpt_path) if ckpt_path.exists() else {"iteration": start, "wall_s": wall_prev}
    return RunResult(run_dir, w, best_w, best_score, int(final["iteration"]), float(final["wall_s"]))


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-train", description=__doc__.split("\n")[0])
    ap.add_argument("config", help="TOML config (configs/train/*.toml)")
    ap.add_argument("-o", "--out", required=True, help="run directory (created; resumed if it holds a checkpoint)")
    ap.add_argument("--seed", type=int, help="override the config's seed")
    ap.add_argument("--iterations", type=int, help="override the config's iterations")
    ap.add_argument("--workers", type=int, help="override the config's workers")
    ap.add_argument("--fresh", action="store_true", help="discard an existing checkpoint in --out")
    ap.add_argument("--rig", type=Path, help="a rig file (pour-sysid): its values become the nominal rig, the "
                                             "randomisation centred on it with widths from its uncertainties")
    ap.add_argument("--quiet", action="store_true", help="no progress lines (iteration, return, time left) on stderr")
    ap.add_argument("--executor", choices=("local", "ray"), default="local",
                    help="where episodes run: 'local' process pool (default) or Ray tasks (pip install './tools[ray]')")
    ap.add_argument("--ray-address", default="local", metavar="auto|HOST:PORT",
                    help="--executor ray: 'local' (a Ray instance of this process), 'auto' (this machine's cluster) "
                         "or a head's HOST:PORT")
    args = ap.parse_args(argv)
    try:
        cfg = cfgmod.load(args.config)
        over = {k: getattr(args, k) for k in ("seed", "iterations", "workers") if getattr(args, k) is not None}
        if over:
            cfg = cfgmod.with_overrides(cfg, **over)
        if args.rig is not None:
            options = srig.centred(cfg.env.options, srig.load(args.rig))
            cfg = cfgmod.validate(dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, options=options)))
        res = train(cfg, args.out, resume=not args.fresh, quiet=args.quiet,
                    make_runner=executors.runner_factory("ray", args.ray_address) if args.executor == "ray" else Runner)
    except (cfgmod.ConfigError, envs.EnvError, TrainError, reinforce.GradientError, executors.ExecutorError,
            srig.RigError) as exc:
        print(f"pour-train: error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps({"run_dir": str(res.run_dir), "iterations": res.iterations, "wall_s": round(res.wall_s, 1),
                      "best_score": res.best_score}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
