# SPDX-License-Identifier: MIT
"""scripts/lib/test_tiers.py, which ./scripts/test.sh runs on each preset: it passes when every label keeps
a test outside `slow`, and refuses, naming the label, a preset whose label is tested only in the slow tier
or whose quick tier runs a slow test. Each case is a small CMake project (no compiler) with its presets."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SOURCE = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCRIPT = SOURCE / "scripts" / "lib" / "test_tiers.py"


def project(tmp: Path, tests: dict[str, str], quick_exclude: str = "^slow$") -> Path:
    """A configured project with one test per entry (name: labels, ';'-separated) and presets t / t-all."""
    lines = ["cmake_minimum_required(VERSION 3.25)", "project(tiers NONE)", "enable_testing()"]
    for name, labels in tests.items():
        lines.append(f'add_test(NAME {name} COMMAND "${{CMAKE_COMMAND}}" -E true)')
        lines.append(f'set_tests_properties({name} PROPERTIES LABELS "{labels}")')
    (tmp / "CMakeLists.txt").write_text("\n".join(lines) + "\n")
    presets = {
        "version": 6,
        "configurePresets": [{"name": "t", "generator": "Unix Makefiles", "binaryDir": "${sourceDir}/build"}],
        "testPresets": [{"name": "t-all", "configurePreset": "t"},
                        {"name": "t", "inherits": "t-all", "filter": {"exclude": {"label": quick_exclude}}}],
    }
    (tmp / "CMakePresets.json").write_text(json.dumps(presets))
    subprocess.run(["cmake", "--preset", "t"], cwd=tmp, check=True, capture_output=True)
    return tmp


def tiers(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], cwd=cwd, capture_output=True, text=True,
                          timeout=60)


def test_every_label_kept_passes(tmp_path):
    proj = project(tmp_path, {"a": "unit", "b": "sim", "c": "sim;slow"})
    res = tiers(proj, "t")
    assert res.returncode == 0, res.stderr
    assert "2 quick tests, 1 slow ones more" in res.stdout


def test_a_label_only_in_the_slow_tier_is_refused_by_name(tmp_path):
    proj = project(tmp_path, {"a": "unit", "b": "ray;slow", "c": "ray;python;slow"})
    res = tiers(proj, "t")
    assert res.returncode == 1
    assert "label(s) python, ray have tests only in the slow tier" in res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr


def test_a_quick_tier_that_runs_slow_tests_is_refused(tmp_path):
    proj = project(tmp_path, {"a": "unit", "b": "unit;slow"}, quick_exclude="^nothing$")
    res = tiers(proj, "t")
    assert res.returncode == 1 and "runs a test labelled 'slow'" in res.stderr


def test_bad_usage_and_unknown_preset(tmp_path):
    proj = project(tmp_path, {"a": "unit"})
    assert tiers(proj).returncode == 2
    res = tiers(proj, "nosuch")
    assert res.returncode == 2 and res.stderr.startswith("test_tiers: ctest --preset nosuch-all cannot list")
    assert res.stderr.count("\n") == 1
    assert "Traceback" not in res.stderr
    assert tiers(proj, "--help").returncode == 0
