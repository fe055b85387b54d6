# SPDX-License-Identifier: MIT
"""Long commands: a table on stdout, or JSON with --json, never both; progress with the time left on
stderr, off with --quiet (pour-sweep here on the toy plant; pour-robust-scale in test_ray_executor.py)."""
import json
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

TOY = SOURCE_DIR / "configs" / "train" / "toy.toml"


def sweep(out, *extra) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pour.eval.sweep", TOY, "-o", out, "--executor", "local",
                           "--seeds", "1", "--iterations", "2", "--held-out", "2", "--grid", "algo.lr=0.1,0.2",
                           *extra], capture_output=True, text=True, timeout=300)


def test_sweep_prints_the_table_alone_with_progress_on_stderr(tmp_path):
    r = sweep(tmp_path / "s")
    assert r.returncode == 0, r.stderr
    assert r.stdout == (tmp_path / "s" / "sweep.md").read_text()
    assert not any(line.lstrip().startswith("{") for line in r.stdout.splitlines())
    assert "2 trials" in r.stderr and "2/2" in r.stderr and "<" in r.stderr  # done/total, elapsed<left


def test_sweep_json_is_one_document_and_quiet_is_silent(tmp_path):
    r = sweep(tmp_path / "s", "--json", "--quiet")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["trials"] == 2 and sorted(row["name"] for row in doc["rows"]) == ["algo.lr=0.1", "algo.lr=0.2"]
    assert r.stderr == ""


@pytest.mark.parametrize("flag", ["--json", "--quiet"])
def test_every_long_command_has_the_flag(flag):
    """The long commands of the issue all take --quiet; the ones with a table also take --json."""
    names = ["pour.eval.sweep", "pour.eval.robust_scale", "pour.eval.results", "pour.eval.plots", "pour.train.trainer"]
    if flag == "--quiet":
        names.append("pour.eval.evaluate robust")
    else:
        names = ["pour.eval.sweep", "pour.eval.robust_scale"]
    for name in names:
        r = subprocess.run([sys.executable, "-m", *name.split(), "--help"], capture_output=True, text=True, timeout=60)
        assert r.returncode == 0 and flag in r.stdout, f"{name}: {r.stdout}"
