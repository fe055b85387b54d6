# SPDX-License-Identifier: MIT
"""What every training method's run shares: its directory, its seeds, its starting parameters and its
greedy validation.

A run lives in one directory: config.json (the config it was started with), log.csv (one row per
iteration) and checkpoint.npz (weights, optimiser state, best weights), each written atomically
(temporary file, then rename), so a killed run resumes with no finished iteration lost and ends
bit-identical to an uninterrupted one. Episode seeds derive from (config seed, stream, iteration),
never from the worker that runs them, so the number of workers does not change the result.
"""
from __future__ import annotations

import csv
import io
import json
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from pour.policy import export
from pour.sim import envs
from pour.train import reinforce
from pour.train.settings import TrainConfig

STREAM_TRAIN, STREAM_VALID, STREAM_TEST = 0, 1, 2
STREAM_SEARCH = 3  # random search's draws (ars.py)
STREAM_INIT = 4    # policy.init = "random"

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


def fmt(v: Any) -> str:
    """A log cell: integers as they are, numbers to 9 significant digits."""
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, str):
        return v
    return f"{float(v):.9g}"


def write_policy_json(path: Path, cfg: TrainConfig, tau_max_nm: float, iteration: int, w: np.ndarray,
                      best_w: np.ndarray, best_score: float) -> None:
    """The exporter's input: deterministic bytes (no times, and not `workers`, which changes the speed
    and nothing else), so a re-run exports the same weights.h whatever its worker count."""
    config = cfg.to_dict()
    del config["workers"]
    export.write_policy(path, cfg.policy.n_actions, cfg.policy.decision_period_ms, tau_max_nm, envs.NORM, w, best_w,
                        config=config, config_digest=cfg.digest(), iteration=iteration, best_score=best_score)


@dataclass
class RunResult:
    run_dir: Path
    w: np.ndarray
    best_w: np.ndarray
    best_score: float
    iterations: int
    wall_s: float


class Run:
    """One run directory as a training method drives it: open() resumes or starts it, save() ends an
    iteration (log first, then policy.json, then the checkpoint: a crash in between leaves a log row the
    resume drops), result() is what train() returns."""

    def __init__(self, cfg: TrainConfig, run_dir: Path):
        self.cfg, self.dir = cfg, run_dir
        self.ckpt, self.log, self.config = run_dir / "checkpoint.npz", run_dir / "log.csv", run_dir / "config.json"
        self.digest = cfg.digest()

    def open(self, resume: bool, quiet: bool, compatible: Callable[[dict[str, Any]], bool] = lambda st: True,
             why: str = "") -> tuple[dict[str, Any] | None, list[dict[str, Any]]]:
        """The checkpoint to resume from (None: a fresh start, whose old checkpoint and log are removed) and
        the log rows before it; writes config.json and the log. TrainError when the checkpoint was made with
        another config (its digest, or compatible(state) false; why names what that needs)."""
        self.dir.mkdir(parents=True, exist_ok=True)
        st, rows = None, []
        if self.ckpt.exists() and resume:
            st = load_checkpoint(self.ckpt)
            if str(st["config_digest"]) != self.digest or not compatible(st):
                raise TrainError(f"{self.dir}: checkpoint was made with a different config "
                                 f"(digest {str(st['config_digest'])[:12]} vs {self.digest[:12]}{why}); "
                                 "use a new run directory or --fresh")
            start = int(st["iteration"])
            rows = [r for r in read_log(self.log) if int(r["iteration"]) < start]
            if not quiet:
                print(f"[pour-train] resuming {self.dir} at iteration {start}", file=sys.stderr)
        else:
            for p in (self.ckpt, self.log):
                if p.exists():
                    p.unlink()
        atomic_write_bytes(self.config, (json.dumps(self.cfg.to_dict(), indent=2, sort_keys=True) + "\n").encode())
        write_log(self.log, rows)
        return st, rows

    def save(self, rows: list[dict[str, Any]], tau_max_nm: float, state: dict[str, Any]) -> None:
        write_log(self.log, rows)
        write_policy_json(self.dir / "policy.json", self.cfg, tau_max_nm, int(state["iteration"]), state["w"],
                          state["best_w"], state["best_score"])
        save_checkpoint(self.ckpt, state)

    def result(self, w: np.ndarray, best_w: np.ndarray, best_score: float, start: int, wall_prev: float) -> RunResult:
        final = load_checkpoint(self.ckpt) if self.ckpt.exists() else {"iteration": start, "wall_s": wall_prev}
        return RunResult(self.dir, w, best_w, best_score, int(final["iteration"]), float(final["wall_s"]))


# --- what the methods share -------------------------------------------------------------------------

def episode_return(ep: envs.Episode, gamma_decision: float) -> float:
    return reinforce.discounted_return(ep.rewards, gamma_decision)


def initial_params(cfg: TrainConfig) -> np.ndarray:
    """The run's starting parameters: zeros, policy.init_beta, or seeded normal(0, init_scale^2)."""
    shape = reinforce.params_shape(cfg.policy.param, cfg.policy.n_actions)
    if cfg.policy.init == "beta":
        return np.array(cfg.policy.init_beta, dtype=np.float64)
    if cfg.policy.init == "random":
        rng = np.random.default_rng(np.random.SeedSequence([cfg.seed, STREAM_INIT]))
        return cfg.policy.init_scale * rng.standard_normal(shape)
    return np.zeros(shape)


def weights(cfg: TrainConfig, params: np.ndarray) -> np.ndarray:
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


def iterations(cfg: TrainConfig, start: int, stop_after: int | None) -> range:
    """The iterations one call runs: from start to the config's end, at most stop_after of them."""
    end = cfg.iterations if stop_after is None else min(cfg.iterations, start + stop_after)
    return range(start, end)


def best_episode(best_ep: dict[str, np.ndarray], eps: Sequence[envs.Episode], rets: np.ndarray, it: int
                 ) -> dict[str, np.ndarray]:
    """The checkpoint's best_ep_* entries: the batch's best episode if it beats the best so far (pour-plots)."""
    ib = int(np.argmax(rets))
    if not best_ep or rets[ib] > float(best_ep["best_ep_return"]):
        e = eps[ib]
        return {"best_ep_x": e.x, "best_ep_actions": e.actions, "best_ep_rewards": e.rewards,
                "best_ep_return": np.array(rets[ib]), "best_ep_iteration": np.array(it)}
    return best_ep


def batch_columns(rets: np.ndarray, eps: Sequence[envs.Episode]) -> dict[str, Any]:
    """The log's columns of one iteration's training episodes (their returns rets)."""
    return {"return_mean": rets.mean(), "return_std": rets.std(), "return_min": rets.min(),
            "return_max": rets.max(), "reward_sum_mean": np.mean([np.sum(e.rewards) for e in eps]),
            "v_target_mean": np.mean([e.metrics["v_target"] for e in eps]),
            "v_spill_mean": np.mean([e.metrics["v_spill"] for e in eps]),
            "finish_s_mean": np.mean([e.metrics["finish_s"] for e in eps])}


def score(episodes: Sequence[envs.Episode], steps: int) -> float:
    """Validation score: the per-tick reward averaged over the episode and over the episodes."""
    return float(np.mean([np.sum(e.rewards) for e in episodes])) / steps


def validate(cfg: TrainConfig, runner: Any, w: np.ndarray, seeds: Sequence[int], it: int
             ) -> tuple[dict[str, float], float]:
    """The greedy validation of W when iteration it is due one (every eval.every and the last): the log's
    eval_* columns (NaN when not due) and the score's standard error."""
    if not cfg.eval.episodes or ((it + 1) % cfg.eval.every != 0 and it != cfg.iterations - 1):
        return dict.fromkeys(("eval_score", "eval_v_target", "eval_v_spill", "eval_finish_s"), np.nan), np.nan
    return greedy_validation(cfg, runner, w, seeds)


def greedy_validation(cfg: TrainConfig, runner: Any, w: np.ndarray, seeds: Sequence[int]
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
