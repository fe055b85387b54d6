# SPDX-License-Identifier: MIT
"""Every program answers --help and --version with exit 0 and does no work for them: the C programs, the
scripts and the pour-* entry points (these also from a wheel: test_wheel_install.py). --version prints the
project's one version (tools/pyproject.toml) and, where weights are compiled in, their hash. The C
programs take --key=value as --key value; host_sim lists its config keys and suggests one for a typo."""
import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest

from conftest import BUILD_DIR, SOURCE_DIR
from lcm_helpers import compiled_weights

VERSION = re.search(r'^version = "([0-9.]+)"$', (SOURCE_DIR / "tools" / "pyproject.toml").read_text(),
                    re.MULTILINE).group(1)
C_PROGRAMS = ["host_sim", "pour_controller", "can_bridge", "fault_pour",
              "bench_fluid", "bench_motor", "bench_slosh", "bench_weights_parse", "lcm_loop_driver"]  # the last five: benchmarks, test drivers
WITH_WEIGHTS = {"pour_controller", "fault_pour"}
SCRIPTS = ["setup.sh", "build.sh", "demo.sh", "test.sh", "bench.sh", "flash.sh"]
ENTRY_POINTS = sorted(e.name for e in metadata.distribution("pour-tools").entry_points
                      if e.group == "console_scripts")


def run(*argv, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=timeout)


def weights_hash() -> str:
    text = compiled_weights(BUILD_DIR).read_text()
    return "0x" + re.search(r"POUR_WEIGHTS_CONTENT_HASH 0x([0-9a-f]{8})u", text).group(1)


@pytest.mark.parametrize("name", C_PROGRAMS)
def test_c_program_help_and_version(name):
    exe = BUILD_DIR / "bin" / name
    r = run(exe, "--help")
    assert r.returncode == 0 and r.stdout.startswith("usage: ") and r.stderr == "", r.stderr
    r = run(exe, "--version")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert r.stdout.startswith(f"{name} {VERSION}")
    assert (weights_hash() in r.stdout) == (name in WITH_WEIGHTS), r.stdout


@pytest.mark.parametrize("name", SCRIPTS)
def test_script_help_and_version_do_no_work(name):
    script = SOURCE_DIR / "scripts" / name
    r = run(script, "--help")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert len(r.stdout.splitlines()) >= 2 and "[setup]" not in r.stdout and "===" not in r.stdout
    r = run(script, "--version")
    assert r.returncode == 0 and r.stdout == f"{name} (pour) {VERSION}\n", r.stdout


@pytest.mark.parametrize("name", ENTRY_POINTS)
def test_entry_point_version(name):
    r = run(Path(sys.executable).parent / name, "--version")
    assert r.returncode == 0 and r.stdout == f"{name} {VERSION}\n", r.stderr


def test_host_sim_same_pour_either_spelling():
    """--key=value is --key value: the same pour, with every value taken (none is a default)."""
    a = run(BUILD_DIR / "bin" / "host_sim", "--baseline=rate", "--rate=2.5", "--seed=7", "--set=episode_s=0.3",
            "--json", "--quiet", timeout=120)
    b = run(BUILD_DIR / "bin" / "host_sim", "--baseline", "rate", "--rate", "2.5", "--seed", "7", "--set",
            "episode_s=0.3", "--json", "--quiet", timeout=120)
    assert a.returncode == b.returncode == 0 and a.stdout == b.stdout, a.stderr + b.stderr
    assert '"controller": "constant rate 2.50 rad/s"' in a.stdout and '"seed": 7,' in a.stdout


def test_host_sim_lists_config_keys():
    r = run(BUILD_DIR / "bin" / "host_sim", "--list-config")
    assert r.returncode == 0, r.stderr
    rows = [x for x in r.stdout.splitlines() if x.startswith("  ")]
    assert len(rows) >= 20
    assert any(re.match(r"^  substeps +\[-\] 1\.\.16 \(integer\), default \d+$", x) for x in rows), r.stdout
    for key in ("dt", "episode_s", "tau_max", "encoder_bits"):
        assert any(x.split()[0] == key for x in rows), key


@pytest.mark.parametrize("key, hint", [
    ("substep", "did you mean 'substeps'?"),
    ("tau_mx", "did you mean 'tau_max'?"),
    ("zzzzzzzz", "host_sim --list-config lists the keys"),
])
def test_host_sim_suggests_a_key(key, hint):
    r = run(BUILD_DIR / "bin" / "host_sim", "--baseline", "rate", "--set", f"{key}=1")
    assert r.returncode == 2 and f"unknown key '{key}'" in r.stderr and hint in r.stderr, r.stderr


def test_host_sim_bad_value_of_a_known_key_has_no_suggestion():
    r = run(BUILD_DIR / "bin" / "host_sim", "--baseline", "rate", "--set", "substeps=99")
    assert r.returncode == 2 and "out of range" in r.stderr and "did you mean" not in r.stderr, r.stderr


def test_bench_fluid_refuses_an_argument_instead_of_timing():
    r = run(BUILD_DIR / "bin" / "bench_fluid", "--steps")
    assert r.returncode == 2 and r.stdout == "" and "takes no arguments" in r.stderr, r.stderr
