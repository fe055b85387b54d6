# SPDX-License-Identifier: MIT
"""Ray across nodes: a two-node cluster on this machine (ray.cluster_utils.Cluster, loopback), rollouts
spread over both nodes with the run unchanged, and pour-sweep's trials on it equal to a local sweep."""
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

# Loopback only: without this Ray rewrites 127.0.0.1 into the machine's outward address (single-machine
# mode; the two-node test cluster and every driver then stay on 127.0.0.1). Read when ray is imported.
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
import ray  # noqa: E402
from ray.cluster_utils import Cluster  # noqa: E402

from pour.eval import evaluate, robust_scale, sweep  # noqa: E402
from pour.train import executors, trainer  # noqa: E402
from test_ray_executor import CountingRunner, _cfg, assert_same_run  # noqa: E402

NODE = {"num_cpus": 1, "node_ip_address": "127.0.0.1", "include_dashboard": False,
        "object_store_memory": 80 * 1024 * 1024}


@pytest.fixture(scope="module")
def two_nodes():
    cluster = Cluster(initialize_head=True, head_node_args=NODE)
    cluster.add_node(**NODE)
    cluster.wait_for_nodes()
    assert executors.connect(cluster.address)   # probed first: an unreachable head fails, never hangs
    yield cluster
    ray.shutdown()
    cluster.shutdown()


class NodeRecorder(CountingRunner):
    nodes: list = []

    def run(self, w, seeds, greedy):
        eps = super().run(w, seeds, greedy)
        NodeRecorder.nodes += self.last_nodes
        return eps


def test_rollouts_spread_over_both_nodes_and_the_run_is_unchanged(two_nodes, tmp_path):
    alive = {n["NodeID"] for n in ray.nodes() if n["Alive"]}
    assert len(alive) == 2 and int(ray.cluster_resources()["CPU"]) == 2
    cfg = _cfg()
    trainer.train(cfg, tmp_path / "local", quiet=True)
    NodeRecorder.nodes = []
    trainer.train(cfg, tmp_path / "ray", quiet=True, make_runner=NodeRecorder)
    assert_same_run(tmp_path / "local", tmp_path / "ray")
    # One batch per CPU of the cluster, each call's two batches spread over the two nodes.
    assert len(NodeRecorder.nodes) == 2 * (4 + 2)
    for i in range(0, len(NodeRecorder.nodes), 2):
        assert set(NodeRecorder.nodes[i:i + 2]) == alive, NodeRecorder.nodes


def _table(out: Path):
    with open(out / "sweep.csv", newline="") as f:
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(f)]


def test_sweep_on_the_cluster_equals_the_local_sweep(two_nodes, tmp_path, source_dir):
    toy = str(source_dir / "configs" / "train" / "toy.toml")
    pts = sweep.points(sweep.parse_grid(["algo.lr=0.05,0.2"]), {}, 0, 0)
    a = sweep.run(toy, tmp_path / "ray", pts, [1, 2], 3, 3, "ray", None, None)
    b = sweep.run(toy, tmp_path / "local", pts, [1, 2], 3, 3, "local", None, None)
    assert _table(tmp_path / "ray") == _table(tmp_path / "local")
    assert (tmp_path / "ray" / "sweep.md").read_bytes() == (tmp_path / "local" / "sweep.md").read_bytes()
    assert [r["name"] for r in a["rows"]] == [r["name"] for r in b["rows"]]
    assert sorted(r["name"] for r in a["rows"]) == ["algo.lr=0.05", "algo.lr=0.2"]
    assert all(r["episodes"] == 2 * 3 for r in a["rows"])
    for png in ("reward_curve.png", "spill_curve.png", "angle.png"):
        assert (tmp_path / "ray" / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # Each trial is an ordinary resumable pour-train run; a finished sweep re-run trains nothing more.
    st = json.loads((tmp_path / "ray" / "runs" / "p01-s2" / "config.json").read_text())
    assert st["seed"] == 2 and st["algo"]["lr"] == 0.2 and st["iterations"] == 3 and st["workers"] == 1
    before = (tmp_path / "ray" / "runs" / "p01-s2" / "checkpoint.npz").read_bytes()
    sweep.run(toy, tmp_path / "ray", pts, [1, 2], 3, 3, "ray", None, None)
    assert (tmp_path / "ray" / "runs" / "p01-s2" / "checkpoint.npz").read_bytes() == before


def test_random_search_is_seeded_and_within_its_ranges():
    r = sweep.parse_range(["algo.lr=0.01:0.3:log", "algo.entropy_coef=0:0.02"])
    a = sweep.points({"algo.batch_episodes": [4, 8]}, r, 3, search_seed=7)
    assert a == sweep.points({"algo.batch_episodes": [4, 8]}, r, 3, search_seed=7)
    assert a != sweep.points({"algo.batch_episodes": [4, 8]}, r, 3, search_seed=8)
    assert len(a) == 6 and {p["algo.batch_episodes"] for p in a} == {4, 8}
    assert all(0.01 <= p["algo.lr"] <= 0.3 and 0 <= p["algo.entropy_coef"] <= 0.02 for p in a)


@pytest.mark.parametrize("args, message", [
    (["--grid", "algo.lr"], "--grid 'algo.lr': expected KEY=V1,V2"),
    (["--grid", "algo.lrr=0.1"], "unknown key(s) lrr"),
    (["--grid", "algo.lr=-1"], "algo.lr = -1"),
    (["--range", "algo.lr=0.3:0.1"], "expected finite LOW < HIGH"),
    (["--range", "algo.lr=0.1:0.3"], "--range needs --random N"),
    (["--seeds", "1,x"], "--seeds '1,x': expected integers"),
    (["--ray-address", "127.0.0.1:1"], "cannot reach the Ray cluster at 127.0.0.1:1"),
])
def test_sweep_cli_errors_are_named(tmp_path, source_dir, args, message):
    r = subprocess.run([sys.executable, "-m", "pour.eval.sweep", str(source_dir / "configs" / "train" / "toy.toml"),
                        "--out", str(tmp_path / "o"), "--iterations", "1", *args],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "pour-sweep: error:" in r.stderr and message in r.stderr, r.stderr
    assert "Traceback" not in r.stderr


def test_robustness_at_scale_on_the_cluster_equals_one_host_sim_run(two_nodes, tmp_path, source_dir, build_dir):
    """6 randomised rigs in 3 tasks of 2 over both nodes: the same episodes as one host_sim process."""
    header = str(source_dir / "policy" / "weights.h")
    rows, meta = robust_scale.run(header, tmp_path, 6, robust_scale.FIRST_SEED, 2, robust_scale.DEFAULT_RAND,
                                  str(build_dir), None, None)
    assert meta["tasks"] == 3 and meta["cluster_cpus"] == 2
    sets = [a for s in (f"{k}={v:g}" for k, v in robust_scale.DEFAULT_RAND.items()) for a in ("--set", s)]
    one = evaluate.run_host_sim(["--policy", header, "--episodes", "6", "--seed", str(robust_scale.FIRST_SEED),
                                 "--quiet", *sets], build_dir)
    doc = json.loads((tmp_path / "robust_scale.json").read_text())
    assert doc["per_episode"] == one["per_episode"]
    assert len({e["liquid_l"] for e in doc["per_episode"]}) == 6   # each rig drew its own fill
    assert rows[0]["episodes"] == 6 and sum(r["episodes"] for r in rows[1:]) == 6
    assert rows[0]["poured_pct"] == pytest.approx(one["poured_pct"], abs=1e-3)
    assert (tmp_path / "robust_scale.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args, message", [
    (["--rigs", "0"], "--rigs 0: expected 1..10000000"),
    (["--per-task", "0"], "--per-task 0: expected 1..100000"),
    (["--repeats", "0"], "--repeats 0: expected 1..1000"),
    (["--repeats", "1001"], "--repeats 1001: expected 1..1000"),
    (["--fill-schedule", "-1"], "--fill-schedule -1.0: expected 0..100 L (0: off)"),
    (["--fill-schedule", "nan"], "--fill-schedule nan: expected 0..100 L (0: off)"),
    (["--set", "rand_fil=0.2"], "--set 'rand_fil=0.2': expected one of rand_fill"),
    (["--set", "rand_fill=lots"], "--set 'rand_fill=lots': 'lots' is not a number"),
    (["--header", "nowhere.h"], "--header nowhere.h: no such file"),
    (["--ray-address", "127.0.0.1:1"], "cannot reach the Ray cluster at 127.0.0.1:1"),
])
def test_robust_scale_cli_errors_are_named(tmp_path, source_dir, args, message):
    base = ["--header", str(source_dir / "policy" / "weights.h"), "--rigs", "2", "--out", str(tmp_path / "o")]
    r = subprocess.run([sys.executable, "-m", "pour.eval.robust_scale", *base, *args],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "pour-robust-scale: error:" in r.stderr and message in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "o").exists()
