# SPDX-License-Identifier: MIT
"""The executors training and evaluation run their work on: in this process, a local pool of forked
processes or of threads, or Ray (`--executor ray`, `--ray-address`), with the connection to a cluster.

Two interfaces. The trainer's episodes: Runner (the local pool, the default) and RayRunner have one
interface (run(w, seeds, greedy) -> episodes in seed order, tau_max_nm, close(), a context manager), so the
training loop does not know which one it drives. Runner forks `workers` processes, each with its own
episode source (one libpoursim world each). Each RayRunner task runs a contiguous batch of episodes (by
default one batch per CPU of the cluster, so the per-task cost of scheduling and of moving the weights is
paid once per batch, not once per episode). The seeds come from the run's config through the driver; a
worker only evaluates (W, seed) -> episode, which is a pure function, so a run on Ray is bit-identical to
the same run on the local pool. Any other work (pour-results' held-out episodes, pour-eval robust's
scenes, pour-sweep's trials, pour-robust-scale's batches): starmap(fn, jobs) here, or RayTasks.starmap on
Ray, fn(*job) for each job, the results in job order, whatever ran them.

Faults: a task whose worker process dies (killed, out of memory, node lost) is run again, up to
`max_retries` times, by Ray; a re-run gives the same episodes because nothing depends on the worker.
An address that cannot be reached fails within a bounded time with an error naming it
(ExecutorError). A KeyboardInterrupt (SIGINT) cancels the outstanding tasks; the run's last checkpoint
is untouched, so the run resumes from it as it does on the local pool.

Workers find libpoursim the way the driver does (pour.paths.sim_library_candidates: $POUR_SIM_LIB,
$POUR_BUILD_DIR/lib, the source tree's build/*/lib); the driver passes $POUR_SIM_LIB and $POUR_BUILD_DIR
to its workers in the job's runtime environment when they are set. On a multi-machine cluster every
node needs the `pour` package (`pip install ./tools[ray]`) and libpoursim at the same path, or
POUR_SIM_LIB pointing at it (docs/training.md, "Training on a Ray cluster").
"""
from __future__ import annotations

import json
import logging
import math
import multiprocessing as mp
import os
import signal
import socket
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Sequence

import numpy as np

from pour import cli
from pour.sim import envs
from pour.train.settings import TrainConfig

# Loopback only unless the user names another host: a local instance never binds a public interface.
LOCAL_NODE_IP = "127.0.0.1"
CONNECT_TIMEOUT_S = 10.0   # TCP probe of HOST:PORT
GCS_TIMEOUT_S = 10.0       # the Ray control service (GCS) answering at HOST:PORT
MAX_RETRIES = 3            # re-runs of a task whose worker died
ENV_FORWARDED = ("POUR_SIM_LIB", "POUR_BUILD_DIR")


class ExecutorError(RuntimeError):
    """Ray is missing, or the cluster cannot be reached or used."""


def import_ray() -> Any:
    try:
        import ray
        import ray.util.scheduling_strategies  # noqa: F401 (RayRunner's node affinity)
    except ImportError as exc:
        raise ExecutorError("--executor ray needs Ray: pip install './tools[ray]' (or run ./scripts/setup.sh)") \
            from exc
    return ray


def runtime_env() -> dict[str, Any]:
    """The job's runtime environment: where the workers find libpoursim, when the driver was told."""
    env_vars = {k: os.environ[k] for k in ENV_FORWARDED if os.environ.get(k)}
    return {"env_vars": env_vars} if env_vars else {}


def parse_address(address: str) -> tuple[str, int]:
    host, sep, port = address.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ExecutorError(f"Ray address {address!r}: expected 'auto', 'local' or HOST:PORT (e.g. 127.0.0.1:6379)")
    return host.strip("[]"), int(port)


def is_loopback(host: str) -> bool:
    return host == "localhost" or host == "::1" or host.startswith("127.")


def keep_loopback(ray: Any) -> None:
    """Makes ray.init keep a loopback address as it is. Ray rewrites 127.0.0.1 into the machine's outward
    address before it connects (so that remote nodes could reach it), but a head started with
    `--node-ip-address=127.0.0.1` listens on loopback alone, and the connection would never succeed.
    Ray reads this switch (its single-machine mode, RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0) at each call."""
    from ray._private import ray_constants
    ray_constants.ENABLE_RAY_CLUSTER = False


def probe(address: str, timeout_s: float = CONNECT_TIMEOUT_S, gcs_timeout_s: float = GCS_TIMEOUT_S) -> None:
    """Checks within a bounded time that a Ray cluster answers at HOST:PORT; ExecutorError naming it if not.

    ray.init(address=...) itself retries an unreachable control service for minutes, so it is never called
    before this probe passes: first a TCP connection (refused, unreachable, no DNS name: at once or within
    timeout_s), then the control service's own handshake (a port that accepts TCP but is not Ray: within
    gcs_timeout_s + 15 s)."""
    host, port = parse_address(address)
    try:
        with socket.create_connection((host, port), timeout=timeout_s):
            pass
    except OSError as exc:
        why = "timed out" if isinstance(exc, TimeoutError) else (exc.strerror or str(exc))
        raise ExecutorError(f"cannot reach the Ray cluster at {address}: {why} (is `ray start --head` running "
                            f"there, and is the port open?)") from exc
    import_ray()
    # The control service's handshake, in a child process killed at the deadline: Ray's client retries
    # for as long as its own config says, whatever the caller wants.
    code = "import sys, ray._raylet as r; r.GcsClient(address=sys.argv[1])"
    env = dict(os.environ, RAY_py_gcs_connect_timeout_s=str(max(1, int(gcs_timeout_s))))
    try:
        r = subprocess.run([sys.executable, "-c", code, f"{host}:{port}"], env=env, capture_output=True,
                           text=True, timeout=gcs_timeout_s + 15)
    except subprocess.TimeoutExpired:
        why = f"no answer within {gcs_timeout_s + 15:.0f} s"
    else:
        if r.returncode == 0:
            return
        lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
        why = lines[-1][:600] if lines else f"exit status {r.returncode}"
    raise ExecutorError(f"cannot reach the Ray cluster at {address}: the port is open but no Ray control "
                        f"service answered ({why})")


def connect(address: str | None, num_cpus: int | None = None) -> bool:
    """Connects this process to Ray unless it already is; returns True if this call did (the caller then
    shuts it down). address None or 'local': a new local instance on loopback with num_cpus CPUs;
    'auto': the cluster this machine's `ray start` runs (or $RAY_ADDRESS); HOST:PORT: that cluster."""
    ray = import_ray()
    if ray.is_initialized():
        return False
    # No dashboard (it needs ray[default] and a port), no worker logs on the trainer's stderr, and only
    # Ray's errors (not its notices) in the trainer's output.
    common = {"include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR,
              "runtime_env": runtime_env() or None}
    if address in (None, "", "local"):
        ray.init(num_cpus=num_cpus, _node_ip_address=LOCAL_NODE_IP, **common)
        return True
    if num_cpus is not None:
        raise ExecutorError("num_cpus applies to a local Ray instance only; a cluster has the CPUs it was started with")
    if address == "auto":
        target = os.environ.get("RAY_ADDRESS") or _current_cluster()
        if not target:
            raise ExecutorError("--ray-address auto: no Ray cluster runs on this machine (start one with "
                                "`ray start --head`, or give HOST:PORT)")
        address = target
    probe(address)
    if is_loopback(parse_address(address)[0]):
        keep_loopback(ray)
    try:
        ray.init(address=address, **common)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        raise ExecutorError(f"cannot connect to the Ray cluster at {address}: {exc}") from exc
    return True


def _current_cluster() -> str | None:
    """The address `ray start --head` on this machine wrote for `ray.init(address='auto')`, as written
    (Ray's own lookup would turn a loopback head's 127.0.0.1 into the machine's outward address)."""
    try:
        from ray._private.utils import read_ray_address
        return read_ray_address() or None
    except Exception:  # a Ray without that helper
        return None


# --- local work: in this process, on forked processes or on threads --------------------------------

def fork_pool(workers: int, initializer: Callable[..., None] | None = None, initargs: tuple = ()) -> Any:
    """A pool of `workers` forked processes (fork: each starts with this process's state, no re-import)."""
    return mp.get_context("fork").Pool(workers, initializer, initargs)


def _star(call: tuple[Callable[..., Any], tuple]) -> Any:
    fn, job = call
    return fn(*job)


def starmap(fn: Callable[..., Any], jobs: Sequence[tuple], workers: int = 1, threads: bool = False,
            desc: str | None = None, quiet: bool = True, unit: str = "task") -> list[Any]:
    """fn(*job) for each job, the results in job order: in this process (one worker, or one job), on
    `workers` forked processes, or on as many threads (threads: fn waits on a subprocess, host_sim, or is
    a closure); a progress bar on stderr unless quiet. An exception of fn is raised as itself."""
    calls = [(fn, tuple(j)) for j in jobs]
    n = max(1, min(workers, len(calls)))
    if n == 1:
        return [_star(c) for c in cli.progress(calls, len(calls), desc, quiet, unit=unit)]
    if threads:
        with ThreadPoolExecutor(max_workers=n) as ex:
            return list(cli.progress(ex.map(_star, calls), len(calls), desc, quiet, unit=unit))
    with fork_pool(n) as pool:
        return list(cli.progress(pool.imap(_star, calls, chunksize=1), len(calls), desc, quiet, unit=unit))


_MADE: dict[str, Any] = {}   # this process's episode sources, by what made them


def cached(make: Callable[..., Any], *args: Any) -> Any:
    """make(*args) (an episode source: envs.make_env, gym_env.PourEnv), built once per process and kept: a
    pool's or a Ray worker runs many tasks."""
    key = json.dumps([make.__module__, make.__qualname__, args], sort_keys=True, default=str)
    made = _MADE.get(key)
    if made is None:
        made = _MADE[key] = make(*args)
    return made


# --- the trainer's local pool (the default executor) --------------------------------------------------

_ENV: Any = None


def _init_worker(env_args: tuple) -> None:
    global _ENV
    _ENV = envs.make_env(*env_args)


def _run(job: tuple) -> envs.Episode:
    w, seed, greedy = job
    return _ENV.rollout(w, seed, greedy)


class Runner:
    """Runs episodes in order on `workers` processes (or in-process for one worker)."""

    def __init__(self, cfg: TrainConfig):
        self.env_args = (cfg.env.kind, cfg.policy.n_actions, cfg.policy.decision_period_ms,
                         cfg.env.episode_s, cfg.env.options)
        _init_worker(self.env_args)  # fail early and clearly in the parent (missing library, bad option)
        self.tau_max_nm = float(_ENV.tau_max_nm)
        self.pool = None
        if cfg.workers > 1:
            self.pool = fork_pool(cfg.workers, _init_worker, (self.env_args,))

    def run(self, w: np.ndarray, seeds: Sequence[int], greedy: bool) -> list[envs.Episode]:
        return self.run_each([w] * len(seeds), seeds, greedy)

    def run_each(self, ws: Sequence[np.ndarray], seeds: Sequence[int], greedy: bool) -> list[envs.Episode]:
        """Episode i runs policy ws[i] on seeds[i] (random search's perturbed policies), in order."""
        jobs = [(w, s, greedy) for w, s in zip(ws, seeds, strict=True)]
        if self.pool is None:
            return [_run(j) for j in jobs]
        return self.pool.map(_run, jobs, chunksize=1)

    def close(self) -> None:
        if self.pool is not None:
            self.pool.close()
            self.pool.join()
            self.pool = None

    def __enter__(self) -> "Runner":
        return self

    def __exit__(self, *exc: Any) -> None:
        if self.pool is not None:
            self.pool.terminate()
            self.pool.join()
            self.pool = None


# --- Ray tasks: plain ones (RayTasks) and the trainer's episodes (RayRunner) -----------------------

def rollout_batch(env_args: tuple, w: np.ndarray, seeds: Sequence[int], greedy: bool,
                  kill_marker: str | None = None) -> tuple[str, list[envs.Episode]]:
    """The body of one Ray task: the episodes of seeds, in order, and the id of the node that ran them.

    The environment is built once per worker process and kept (cached).
    kill_marker is fault injection for the tests: the first task to create that file SIGKILLs its own
    worker process, as the OOM killer or a lost node would."""
    if kill_marker is not None:
        try:
            fd = os.open(kill_marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            pass
        else:
            os.write(fd, str(os.getpid()).encode())
            os.close(fd)
            os.kill(os.getpid(), signal.SIGKILL)
    env = cached(envs.make_env, *env_args)
    import ray
    node = ray.get_runtime_context().get_node_id()
    return node, [env.rollout(w, int(s), greedy) for s in seeds]


def batches(seeds: Sequence[int], n_tasks: int) -> list[list[int]]:
    """seeds cut into n_tasks contiguous batches whose sizes differ by at most one, in order."""
    n = len(seeds)
    n_tasks = max(1, min(n_tasks, n))
    q, r = divmod(n, n_tasks)
    out, i = [], 0
    for k in range(n_tasks):
        m = q + (1 if k < r else 0)
        out.append([int(s) for s in seeds[i:i + m]])
        i += m
    return out


class RayTasks:
    """Plain Ray tasks of one CPU each (pour-sweep's trials, pour-robust-scale's batches), on a connection
    made as connect() makes it and shut down at the end if this made it; a context manager."""

    def __init__(self, address: str | None = None, num_cpus: int | None = None):
        self.ray = import_ray()
        self.owns_ray = connect(address, num_cpus)

    def cpus(self) -> int:
        """The cluster's CPUs (at least 1)."""
        return max(1, int(self.ray.cluster_resources().get("CPU", 1)))

    def starmap(self, fn: Callable[..., Any], jobs: Sequence[tuple], desc: str, quiet: bool = False) -> list[Any]:
        """starmap() on Ray: one task a job, each re-run up to MAX_RETRIES times if its worker dies; the results
        in job order, with gather()'s progress bar; an error or Ctrl-C cancels the unfinished tasks."""
        task = self.ray.remote(num_cpus=1, max_retries=MAX_RETRIES, retry_exceptions=False)(fn)
        return gather(self.ray, [task.remote(*j) for j in jobs], desc, quiet)

    def close(self) -> None:
        if self.owns_ray and self.ray.is_initialized():
            self.ray.shutdown()
        self.owns_ray = False

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


class RayRunner(RayTasks):
    """Runner's interface on Ray tasks. address: see connect(); episodes_per_task: batch size
    (default: the episodes of a call spread evenly, one batch per CPU of the cluster)."""

    def __init__(self, cfg: Any, address: str | None = None, num_cpus: int | None = None,
                 episodes_per_task: int | None = None, max_retries: int = MAX_RETRIES,
                 kill_marker: str | None = None):
        if episodes_per_task is not None and episodes_per_task < 1:
            raise ExecutorError(f"episodes_per_task = {episodes_per_task}: expected >= 1")
        self.env_args = (cfg.env.kind, cfg.policy.n_actions, cfg.policy.decision_period_ms,
                         cfg.env.episode_s, cfg.env.options)
        # Fail early and clearly in the driver (missing library, bad option), as the local runner does.
        self.tau_max_nm = float(envs.make_env(*self.env_args).tau_max_nm)
        super().__init__(address, num_cpus)
        self.episodes_per_task = episodes_per_task
        self.kill_marker = kill_marker
        self.max_retries = max_retries
        self.task = self.ray.remote(max_retries=max_retries, retry_exceptions=False, num_cpus=1)(rollout_batch)
        self.pending: list[Any] = []
        self.last_nodes: list[str] = []   # node id of each task of the last run(), in task order

    def slots(self) -> list[str]:
        """One entry per CPU of the cluster's live nodes, the nodes interleaved: batch i goes to slot i.

        Placing each batch on a node (soft affinity) spreads a call's batches over the nodes in
        proportion to their CPUs; Ray's own placement packs short tasks onto the driver's node first. Soft:
        when that node is busy or gone, Ray runs the batch elsewhere (and re-runs it if the node dies)."""
        per_node = [(n["NodeID"], int(n.get("Resources", {}).get("CPU", 0)))
                    for n in self.ray.nodes() if n.get("Alive")]
        out, k = [], 0
        while any(c > k for _, c in per_node):
            out += [node for node, c in per_node if c > k]
            k += 1
        return out or [""]

    def run(self, w: np.ndarray, seeds: Sequence[int], greedy: bool) -> list[envs.Episode]:
        return self.run_each([w] * len(seeds), seeds, greedy)

    def run_each(self, ws: Sequence[np.ndarray], seeds: Sequence[int], greedy: bool) -> list[envs.Episode]:
        """Runner.run_each on Ray. Consecutive episodes of one policy (the same array) form a group whose
        weights are sent once; a lone group is cut into one batch per CPU, several groups share the CPUs."""
        if not len(seeds):
            return []
        if len(ws) != len(seeds):
            raise ValueError(f"run_each: {len(ws)} policies for {len(seeds)} seeds")
        groups, i = [], 0
        while i < len(seeds):
            j = i + 1
            while j < len(seeds) and ws[j] is ws[i]:
                j += 1
            groups.append((ws[i], list(seeds[i:j])))
            i = j
        slots = self.slots()
        affinity = self.ray.util.scheduling_strategies.NodeAffinitySchedulingStrategy
        self.pending, k = [], 0
        for w, group in groups:
            n_tasks = math.ceil(len(group) / self.episodes_per_task) if self.episodes_per_task \
                else max(1, len(slots) // len(groups))
            w_ref = self.ray.put(np.asarray(w))
            for b in batches(group, n_tasks):
                slot = slots[k % len(slots)]
                k += 1
                self.pending.append(
                    self.task.options(scheduling_strategy=affinity(slot, soft=True) if slot else None)
                    .remote(self.env_args, w_ref, b, bool(greedy), self.kill_marker))
        # On KeyboardInterrupt the tasks stay in self.pending, and close() (the trainer's `with`) cancels them.
        try:
            results = self.ray.get(self.pending)
        except self.ray.exceptions.RayTaskError as exc:
            # An exception inside the episode code (e.g. EnvError): re-raise the original, so the trainer
            # reports it as it would from the local pool.
            self.cancel()
            if isinstance(getattr(exc, "cause", None), Exception):
                raise exc.cause from None
            raise
        except self.ray.exceptions.WorkerCrashedError as exc:
            self.cancel()
            raise ExecutorError(f"a rollout task's worker died {self.max_retries + 1} times: {exc}") from exc
        self.pending = []
        self.last_nodes = [node for node, _ in results]
        return [ep for _, eps in results for ep in eps]

    def cancel(self) -> None:
        """Cancels the tasks of an unfinished run()."""
        cancel_all(self.ray, self.pending)
        self.pending = []

    def close(self) -> None:
        self.cancel()
        super().close()


def gather(ray: Any, refs: Sequence[Any], desc: str, quiet: bool = False) -> list[Any]:
    """ray.get(refs), in their order, with a progress bar on stderr (tasks done, time left) as they finish.
    On an error or Ctrl-C the unfinished tasks are cancelled, and a task's own exception is raised as itself."""
    try:
        pending = list(refs)
        with cli.bar(len(pending), desc, quiet, unit="task") as b:
            while pending:
                ready, pending = ray.wait(pending, num_returns=1)
                ray.get(ready)  # a task's error now, not after the rest
                b.update(len(ready))
        return ray.get(list(refs))
    except BaseException as exc:
        cancel_all(ray, refs)
        if isinstance(exc, ray.exceptions.RayTaskError) and isinstance(getattr(exc, "cause", None), Exception):
            raise exc.cause from None
        raise


def cancel_all(ray: Any, refs: Sequence[Any]) -> None:
    """Cancels the tasks of refs that have not finished (force: their workers are killed). Only unfinished
    ones: Ray 2.60's driver aborts on a cancel of some finished tasks (task_manager.cc check failure)."""
    if not refs:
        return
    done, _ = ray.wait(list(refs), num_returns=len(refs), timeout=0)
    finished = set(done)
    for ref in refs:
        if ref not in finished:
            try:
                ray.cancel(ref, force=True)
            except Exception:  # already finished or gone meanwhile: nothing to stop
                pass


def runner_factory(executor: str, address: str | None = None) -> Any:
    """cfg -> runner for `pour-train --executor`: 'local' (Runner, the default) or 'ray'."""
    if executor == "local":
        return Runner
    if executor == "ray":
        # A local instance gets the config's `workers` CPUs, as the local pool gets that many processes.
        local = address in (None, "", "local")
        return lambda cfg: RayRunner(cfg, address=address, num_cpus=cfg.workers if local else None)
    raise ExecutorError(f"--executor {executor!r}: expected 'local' or 'ray'")

