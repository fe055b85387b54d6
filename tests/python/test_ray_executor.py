# SPDX-License-Identifier: MIT
"""pour-train on Ray (tools/pour/train/executors.py), on a local Ray instance of 2 CPUs on loopback.

A run on Ray is bit-identical to the same run on the local pool (toy plant and libpoursim), a worker
killed mid-run is retried with the result unchanged, an unreachable address fails fast naming it, and
SIGINT leaves a run that resumes from its last checkpoint to the uninterrupted result.
"""
import csv
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

# Loopback only: without this Ray rewrites 127.0.0.1 into the machine's outward address (single-machine
# mode; the two-node test cluster and every driver then stay on 127.0.0.1). Read when ray is imported.
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
import ray  # noqa: E402

from pour.train import config as cfgmod  # noqa: E402
from pour.sim import envs  # noqa: E402
from pour.train import executors, rundir, trainer  # noqa: E402

TOY = {"seed": 11, "iterations": 4, "workers": 2,
       "policy": {"n_actions": 5, "decision_period_ms": 10},
       "algo": {"batch_episodes": 6, "lr": 0.1},
       "eval": {"every": 2, "episodes": 3},
       "env": {"kind": "toy", "episode_s": 2.0}}


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray instance for the module (starting one costs seconds): 2 CPUs, loopback, no dashboard."""
    assert executors.connect("local", num_cpus=2)
    yield ray
    ray.shutdown()


def _cfg(d=None, **top):
    d = json.loads(json.dumps(d or TOY))
    d.update(top)
    return cfgmod.from_dict(d)


def _rows(run_dir):
    with open(Path(run_dir) / "log.csv", newline="") as f:
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(f)]


def assert_same_run(a: Path, b: Path) -> None:
    """policy.json byte for byte, every checkpoint array byte for byte (but the wall time), the log's rows."""
    assert (a / "policy.json").read_bytes() == (b / "policy.json").read_bytes()
    with np.load(a / "checkpoint.npz") as za, np.load(b / "checkpoint.npz") as zb:
        assert za.files == zb.files
        for k in za.files:
            if k != "wall_s":
                assert za[k].dtype == zb[k].dtype and za[k].tobytes() == zb[k].tobytes(), k
    assert _rows(a) == _rows(b)


class CountingRunner(executors.RayRunner):
    tasks = 0

    def run(self, w, seeds, greedy):
        eps = super().run(w, seeds, greedy)
        CountingRunner.tasks += len(self.last_nodes)
        return eps


def test_toy_run_on_ray_is_bit_identical_to_the_local_pool(local_ray, tmp_path):
    cfg = _cfg()
    trainer.train(cfg, tmp_path / "local", quiet=True)
    CountingRunner.tasks = 0
    res = trainer.train(cfg, tmp_path / "ray", quiet=True,
                      make_runner=lambda c: CountingRunner(c, episodes_per_task=2))
    assert res.iterations == 4
    assert_same_run(tmp_path / "local", tmp_path / "ray")
    # 4 iterations x 3 tasks of 2 training episodes, 2 evaluations x 2 tasks (2 + 1 episodes).
    assert CountingRunner.tasks == 4 * 3 + 2 * 2
    # A different seed gives a different run: the comparison can fail.
    trainer.train(_cfg(seed=12), tmp_path / "other", quiet=True, make_runner=executors.RayRunner)
    assert (tmp_path / "other" / "policy.json").read_bytes() != (tmp_path / "local" / "policy.json").read_bytes()


@pytest.mark.parametrize("search", [
    {"algo": {"kind": "ars", "entropy_coef": 0.0}, "ars": {"directions": 3, "top": 2, "noise": 0.5}},
    {"algo": {"kind": "cem", "entropy_coef": 0.0}, "cem": {"population": 5, "elites": 2}}])
def test_search_runs_on_ray_are_bit_identical_to_the_local_pool(local_ray, tmp_path, search):
    # One policy per episode (run_each): each distinct W is its own group of tasks.
    d = json.loads(json.dumps(TOY))
    d.update(search)
    d["policy"]["param"] = "feedback"
    cfg = cfgmod.from_dict(d)
    trainer.train(cfg, tmp_path / "local", quiet=True)
    trainer.train(cfg, tmp_path / "ray", quiet=True, make_runner=executors.RayRunner)
    assert_same_run(tmp_path / "local", tmp_path / "ray")


def test_simulator_run_on_ray_is_bit_identical_and_workers_find_libpoursim(local_ray, tmp_path):
    """Two iterations on libpoursim; the workers load the library the driver's environment names."""
    beta = [0.0, 0.0, 0.0, 0.0, 0.0, 0.9]
    d = {"seed": 3, "iterations": 2, "workers": 2,
         "policy": {"n_actions": 11, "param": "feedback", "init": "beta", "init_beta": beta},
         "algo": {"batch_episodes": 4}, "eval": {"every": 1, "episodes": 2},
         "env": {"kind": "sim", "episode_s": 0.5}}
    cfg = _cfg(d)
    trainer.train(cfg, tmp_path / "local", quiet=True)
    trainer.train(cfg, tmp_path / "ray", quiet=True, make_runner=executors.RayRunner)
    assert_same_run(tmp_path / "local", tmp_path / "ray")
    w0 = rundir.weights(cfg, np.array(beta))
    assert json.loads((tmp_path / "ray" / "policy.json").read_text())["w"] != w0.tolist()


def test_batches_are_contiguous_balanced_and_in_order():
    assert executors.batches(list(range(7)), 3) == [[0, 1, 2], [3, 4], [5, 6]]
    assert executors.batches([5, 6], 8) == [[5], [6]]
    assert executors.batches(list(range(4)), 1) == [[0, 1, 2, 3]]


def test_a_killed_worker_is_retried_and_the_run_is_unchanged(local_ray, tmp_path):
    cfg = _cfg()
    trainer.train(cfg, tmp_path / "local", quiet=True)
    marker = tmp_path / "killed"
    trainer.train(cfg, tmp_path / "ray", quiet=True,
                make_runner=lambda c: executors.RayRunner(c, max_retries=2, kill_marker=str(marker)))
    # The first task SIGKILLed its own worker process (the marker holds its pid), and that process is gone.
    pid = int(marker.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
    assert_same_run(tmp_path / "local", tmp_path / "ray")


def test_without_retries_a_killed_worker_fails_the_run_with_a_clear_error(local_ray, tmp_path):
    marker = tmp_path / "killed"
    with pytest.raises(executors.ExecutorError, match="worker died 1 times"):
        trainer.train(_cfg(), tmp_path / "ray", quiet=True,
                    make_runner=lambda c: executors.RayRunner(c, max_retries=0, kill_marker=str(marker)))
    assert marker.exists()


def test_an_error_in_an_episode_is_reported_as_on_the_local_pool(local_ray, tmp_path):
    """A bad option fails in the driver before any task runs; inside a task, the original error returns."""
    with pytest.raises(envs.EnvError, match="unknown option 'bogus'"):
        executors.RayRunner(_cfg(env={"kind": "toy", "episode_s": 2.0, "options": {"bogus": 1}}))
    r = executors.RayRunner(_cfg())
    with pytest.raises(ValueError, match="matmul|shape|align"):
        r.run(np.zeros((3, 3)), [1, 2], False)   # W of the wrong shape: numpy's error, from the worker
    r.close()


def _free_port() -> int:
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def _toml(cfg_file: Path, iterations: int) -> None:
    cfg_file.write_text(f"seed = 11\niterations = {iterations}\nworkers = 2\n"
                        "[policy]\nn_actions = 5\n[algo]\nbatch_episodes = 6\nlr = 0.1\n"
                        "[eval]\nevery = 2\nepisodes = 3\n[env]\nkind = \"toy\"\nepisode_s = 10.0\n")


def test_unreachable_address_fails_fast_naming_it(tmp_path):
    cfg_file = tmp_path / "toy.toml"
    _toml(cfg_file, 2)
    addr = f"127.0.0.1:{_free_port()}"
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "pour.train.trainer", str(cfg_file), "--out", str(tmp_path / "o"),
                        "--executor", "ray", "--ray-address", addr], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert f"pour-train: error: cannot reach the Ray cluster at {addr}: Connection refused" in r.stderr
    assert "Traceback" not in r.stderr
    assert time.monotonic() - t0 < 60
    assert not (tmp_path / "o" / "checkpoint.npz").exists()


def test_a_port_that_is_not_ray_fails_within_a_bounded_time_naming_it():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(4)   # accepts TCP, never speaks Ray's protocol
        addr = f"127.0.0.1:{s.getsockname()[1]}"
        t0 = time.monotonic()
        with pytest.raises(executors.ExecutorError, match=f"at {addr}: the port is open but no Ray"):
            executors.probe(addr, timeout_s=2, gcs_timeout_s=3)
        assert time.monotonic() - t0 < 3 + 15 + 5


@pytest.mark.parametrize("bad", ["nohost", "127.0.0.1:", ":6379", "127.0.0.1:99999", "127.0.0.1:x"])
def test_malformed_addresses_are_named(bad):
    with pytest.raises(executors.ExecutorError, match=f"Ray address {bad!r}: expected"):
        executors.probe(bad)


def _checkpointed(run: Path) -> int:
    """Iterations in the run's checkpoint (written whole, by rename), 0 before the first."""
    try:
        with np.load(run / "checkpoint.npz") as z:
            return int(z["iteration"])
    except FileNotFoundError:
        return 0


def test_sigint_leaves_a_run_that_resumes_to_the_uninterrupted_result(tmp_path):
    cfg_file = tmp_path / "toy.toml"
    _toml(cfg_file, 12)
    run = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "pour.train.trainer", str(cfg_file), "--out", str(run), "--quiet",
                             "--executor", "ray"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None and _checkpointed(run) < 2:
            time.sleep(0.01)
        assert proc.poll() is None, "the run finished before it could be interrupted: " + proc.stderr.read()
        proc.send_signal(signal.SIGINT)
        err = proc.communicate(timeout=60)[1]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode != 0, err
    assert "KeyboardInterrupt" in err
    done = _checkpointed(run)
    assert 2 <= done < 12
    assert not list(run.glob("*.tmp"))
    cfg = cfgmod.load(cfg_file)
    resumed = trainer.train(cfg, run, quiet=True)
    assert resumed.iterations == 12
    trainer.train(cfg, tmp_path / "ref", quiet=True)
    assert_same_run(run, tmp_path / "ref")


@pytest.mark.parametrize("extra", [[], ["--json", "--quiet"]])
def test_robust_scale_prints_a_table_or_json_never_both(tmp_path, source_dir, extra):
    """pour-robust-scale: the table alone on stdout (progress with the time left on stderr), or with --json one
    JSON document alone (and --quiet: nothing on stderr)."""
    out = tmp_path / "r"
    r = subprocess.run([sys.executable, "-m", "pour.eval.robust_scale", "--header", source_dir / "policy" / "weights.h",
                        "--rigs", "2", "--per-task", "1", "--num-cpus", "1", "-o", out, *extra], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    if extra:
        doc = json.loads(r.stdout)
        assert doc["rigs"] == 2 and doc["tasks"] == 2 and doc["rows"][0]["episodes"] == 2
        assert "2/2" not in r.stderr
    else:
        assert r.stdout == (out / "robust_scale.md").read_text() and "| scene | episodes |" in r.stdout
        assert not any(line.lstrip().startswith("{") for line in r.stdout.splitlines())
        assert "2 rigs" in r.stderr and "2/2" in r.stderr and "<" in r.stderr


def test_robust_scale_repeats_each_rig_with_its_fill_stepped_and_judges_the_mean(tmp_path, source_dir):
    """--repeats 2 over 2 rigs: 4 episodes, each seed twice, the second repeat holding 1e-4 more liquid than the
    first (the rig's own draw, scaled), and the table's rows judging 2 rigs by their means."""
    out = tmp_path / "r"
    r = subprocess.run([sys.executable, "-m", "pour.eval.robust_scale", "--header", source_dir / "policy" / "weights.h",
                        "--rigs", "2", "--repeats", "2", "--num-cpus", "2", "--quiet", "--json", "-o", out],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    doc = json.loads((out / "robust_scale.json").read_text())
    assert json.loads(r.stdout)["repeats"] == 2 and doc["rows"][0]["episodes"] == 2
    eps = {(e["seed"], e["repeat"]): e for e in doc["per_episode"]}
    assert sorted(eps) == [(s, k) for s in (3_000_000, 3_000_001) for k in (0, 1)]
    for s in (3_000_000, 3_000_001):
        ratio = eps[s, 1]["liquid_l"] / eps[s, 0]["liquid_l"]
        assert abs(ratio - 1 - 1e-4) < 3e-5, ratio    # the rig's own fill, stepped; not the nominal's
        rig = next(g for g in doc["per_rig"] if g["seed"] == s)
        assert rig["spilled_pct"] == (eps[s, 0]["spilled_pct"] + eps[s, 1]["spilled_pct"]) / 2
    md = (out / "robust_scale.md").read_text()
    assert "Each rig ran 2 times" in md and "| scene | rigs |" in md   # a row counts rigs, each a mean


def test_robust_scale_fill_schedule_configures_the_rigs_above_it(tmp_path, source_dir):
    """--fill-schedule 5 over 2 rigs (both hold 8-12 L): each rig's firmware gets the schedule's knee from its
    own fill, so its pour, at 0.16 rad/s past the knee, finishes after 4 s or not at all (as shipped these rigs
    finish near 2 s); the run records the setting in its JSON and the table's heading."""
    out = tmp_path / "f"
    r = subprocess.run([sys.executable, "-m", "pour.eval.robust_scale", "--header", source_dir / "policy" / "weights.h",
                        "--rigs", "2", "--fill-schedule", "5", "--num-cpus", "2", "--quiet", "-o", out],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    doc = json.loads((out / "robust_scale.json").read_text())
    assert doc["fill_schedule_l"] == 5.0 and len(doc["per_episode"]) == 2
    for e in doc["per_episode"]:
        assert e["liquid_l"] > 5 and (e["finish_s"] < 0 or e["finish_s"] > 4), e
    assert "fill_schedule_l=5" in (out / "robust_scale.md").read_text()
