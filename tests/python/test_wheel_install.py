# SPDX-License-Identifier: MIT
"""The package as a user installs it: a wheel built from the checkout (libpoursim compiled into it by
tools/CMakeLists.txt), installed into a fresh venv in a folder outside the source tree, with no build tree
and no POUR_SIM_LIB to lean on. Every pour-* entry point answers --help and --version; the DBC and the LCM
types come from the wheel's package data (pour-can-dbc, pour-can-bus-load, pour-lcm-cmd, pour-lcmlog on a
log recorded with lcm-logger); the simulator is the wheel's own library (the Gymnasium env, pour-sysid). A
wheel build without Eigen or without a compiler stops with one line saying what to install.

No network: the wheel builds without build isolation in the project's venv (scikit-build-core, pyb2d3,
cmeel-eigen and lcm from the lock), installs with --no-index --no-deps, and the fresh venv sees its
dependencies (the lock's packages) through a .pth line to the project venv's site-packages, after its own,
so `pour` itself comes from the wheel alone."""
import csv
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import pytest

from conftest import BUILD_DIR, SOURCE_DIR
from lcm_helpers import record_pour, url


def run(argv, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=300, **kw)


# What the wheel is built from: the package, the C and C++ sources of libpoursim and their CMake, the DBC and
# the LCM types. Copied, so that a build leaves the source tree as it was.
WHEEL_SOURCES = ["CMakeLists.txt", "cmake", "firmware", "host_sim", "can", "lcmtypes", "tools", "configs/sim"]


def pip_wheel(src: Path, out: Path, *extra, env=None) -> subprocess.CompletedProcess:
    return run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
                "--disable-pip-version-check", src / "tools", "-w", out, *extra], env=env)


@pytest.fixture(scope="module")
def checkout_copy():
    root = Path(tempfile.mkdtemp(prefix="pour-wheel-"))
    assert SOURCE_DIR.resolve() not in root.resolve().parents
    (root / "src").mkdir()
    try:
        for name in WHEEL_SOURCES:
            if (SOURCE_DIR / name).is_dir():
                shutil.copytree(SOURCE_DIR / name, root / "src" / name, ignore=shutil.ignore_patterns(
                    "*.egg-info", "build", "__pycache__"))
            else:
                shutil.copyfile(SOURCE_DIR / name, root / "src" / name)
        yield root
    finally:
        shutil.rmtree(root, ignore_errors=True)


@pytest.fixture(scope="module")
def installed(checkout_copy):
    """(venv bin folder, a working folder outside the checkout, an environment without our build tree)."""
    root = checkout_copy
    r = pip_wheel(root / "src", root / "wheels")
    assert r.returncode == 0, r.stderr
    (wheel,) = (root / "wheels").glob("pour_tools-*.whl")
    venv = root / "venv"
    r = run(["/usr/bin/python3", "-m", "venv", venv])
    assert r.returncode == 0, r.stderr
    r = run([venv / "bin" / "python", "-m", "pip", "install", "-q", "--no-index", "--no-deps",
             "--disable-pip-version-check", wheel])
    assert r.returncode == 0, r.stderr
    site = Path(run([venv / "bin" / "python", "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"])
                .stdout.strip())
    (site / "zz_pour_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    work = root / "work"
    work.mkdir()
    env = {k: v for k, v in os.environ.items()
           if k not in ("POUR_BUILD_DIR", "POUR_SOURCE_DIR", "POUR_SIM_LIB", "POUR_LCMTYPES_PYTHON",
                        "PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = f"{venv / 'bin'}:/usr/bin:/bin"
    yield venv / "bin", work, env


def entry_points(bin_dir: Path) -> list[str]:
    code = ("from importlib import metadata; "
            "print('\\n'.join(sorted(e.name for e in metadata.distribution('pour-tools').entry_points "
            "if e.group == 'console_scripts')))")
    return run([bin_dir / "python", "-c", code]).stdout.split()


def test_pour_is_imported_from_the_wheel(installed):
    bin_dir, work, env = installed
    r = run([bin_dir / "python", "-c", "import pour, pour.paths as p; print(pour.__file__); print(p.data_file('pour.dbc'))"],
            cwd=work, env=env)
    assert r.returncode == 0, r.stderr
    module, dbc = r.stdout.split()
    assert Path(module).is_relative_to(bin_dir.parent) and Path(dbc).is_relative_to(bin_dir.parent)


def test_every_entry_point_answers_help_and_version(installed):
    bin_dir, work, env = installed
    names = entry_points(bin_dir)
    assert len(names) >= 15 and "pour-train" in names and "pour-lcmlog" in names
    for name in names:
        for flag in ("--help", "--version"):
            r = run([bin_dir / name, flag], cwd=work, env=env)
            assert r.returncode == 0 and "Traceback" not in r.stderr, f"{name} {flag}: {r.stderr}"
            assert name in r.stdout, f"{name} {flag}: {r.stdout}"


def test_can_tools_read_the_packaged_dbc(installed):
    bin_dir, work, env = installed
    r = run([bin_dir / "pour-can-dbc", "--node", "1"], cwd=work, env=env)
    assert r.returncode == 0, r.stderr
    assert "This file is for node id 1." in r.stdout and "BO_ 33 Heartbeat" in r.stdout  # cmd 1 of node 1
    r = run([bin_dir / "pour-can-bus-load"], cwd=work, env=env)
    assert r.returncode == 0, r.stderr
    assert "bus load at 1 Mbit/s" in r.stdout


def test_lcm_tools_read_the_packaged_types(installed, tmp_path):
    bin_dir, work, env = installed
    r = run([bin_dir / "pour-lcm-cmd", "--help"], cwd=work, env=env)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    r = run([bin_dir / "pour-lcm-cmd", "--clear", "--url", "memq://"], cwd=work, env=env)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    r = run([bin_dir / "python", "-c", "from pour.lcm import messages; print(messages.load().__file__)"],
            cwd=work, env=env)
    assert r.returncode == 0, r.stderr
    assert Path(r.stdout.strip()).is_relative_to(bin_dir.parent)
    log, _ = record_pour(BUILD_DIR, tmp_path / "pour.lcmlog", url(47), seconds=1)
    r = run([bin_dir / "pour-lcmlog", log, "--json"], cwd=work, env=env)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    (ep,) = json.loads(r.stdout)["episodes"]
    assert ep["last_seq"] >= 900


# Run in the wheel's venv: a program that imports gymnasium, never pour, and makes pour's id. The start-up
# hook (_pour_gymnasium.pth) must not have imported either before the program did.
GYM_PROGRAM = r"""
import json, sys
assert "gymnasium" not in sys.modules and "pour" not in sys.modules, "imported at start-up"
import gymnasium as gym
from gymnasium.utils.env_checker import check_env
assert "pour.sim.gym_env" not in sys.modules  # registered lazily: the env module loads at make
env = gym.make("pour/Pour-v0", render_mode="rgb_array")
assert env.spec.max_episode_steps == 1000
check_env(env.unwrapped, skip_render_check=False)
obs, info = env.reset(seed=int(sys.argv[1]))
v_target, v_spill = [], []
for a in sys.argv[2].split(","):
    obs, reward, terminated, truncated, info = env.step(int(a))
    v_target.append(info["v_target"])
    v_spill.append(info["v_spill"])
import pour.libpoursim
print(json.dumps({"v_target": v_target, "v_spill": v_spill, "truncated": truncated,
                  "frame": list(env.render().shape), "module": sys.modules["pour"].__file__,
                  "lib": str(pour.libpoursim.candidates()[0]), "loaded": pour.libpoursim.load()._name}))
"""


def test_gymnasium_makes_pour_ids_without_importing_pour(installed, source_dir, tmp_path):
    """gymnasium.make("pour/Pour-v0", render_mode="rgb_array") in a program that never imports pour; check_env
    passes; reset(seed=1000001), then host_sim's own decisions, give host_sim --seed 1000001's episode."""
    bin_dir, work, env = installed
    seed = 1000001
    steps = tmp_path / "steps.csv"
    r = run([BUILD_DIR / "bin" / "host_sim", "--policy", source_dir / "policy" / "weights.h", "--seed", seed,
             "--json", "--quiet", "--csv", steps])
    assert r.returncode == 0, r.stderr
    want = json.loads(r.stdout)
    with steps.open() as f:
        rows = list(csv.DictReader(f))
    # One decision per 10 ms: the action in force at its first tick; the volumes after its last.
    actions = [row["action"] for row in rows[::10]]
    assert len(actions) == 1000 and len(set(actions)) > 1
    r = run([bin_dir / "python", "-c", GYM_PROGRAM, seed, ",".join(actions)], cwd=work, env=env)
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout)
    assert Path(got["module"]).is_relative_to(bin_dir.parent)  # pour came from the wheel, through the hook
    assert got["loaded"] == got["lib"] and Path(got["lib"]).is_relative_to(bin_dir.parent)  # and its libpoursim
    assert got["truncated"] and got["frame"][2] == 3
    # The same episode: host_sim's figures, and its volumes (%.6f in the CSV) after every decision.
    assert round(100.0 * got["v_target"][-1], 3) == want["poured_pct"] and want["poured_pct"] > 90
    assert round(100.0 * got["v_spill"][-1], 3) == want["spilled_pct"]
    assert [round(v, 6) for v in got["v_target"]] == [float(row["v_target"]) for row in rows[9::10]]
    assert [round(v, 6) for v in got["v_spill"]] == [float(row["v_spill"]) for row in rows[9::10]]


def test_pour_sysid_fits_with_the_wheels_library(installed, tmp_path):
    bin_dir, work, env = installed
    log = tmp_path / "identify.log"
    r = run([BUILD_DIR / "bin" / "host_sim", "--experiment", "identify", "--candump", log, "--seed", 1, "--quiet"])
    assert r.returncode == 0, r.stderr
    r = run([bin_dir / "pour-sysid", log, "--out", tmp_path / "rig.toml", "--json"], cwd=work, env=env)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert "inertia" in json.loads(r.stdout) and (tmp_path / "rig.toml").is_file()


def one_line(r: subprocess.CompletedProcess, start: str) -> str:
    (line,) = [ln.strip() for ln in (r.stdout + r.stderr).splitlines() if ln.strip().startswith(start)]
    return line


def test_a_wheel_build_without_eigen_says_what_to_install(checkout_copy, tmp_path):
    r = pip_wheel(checkout_copy / "src", tmp_path, "--config-settings=cmake.define.CMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON")
    assert r.returncode != 0 and not list(tmp_path.glob("*.whl"))
    assert one_line(r, "pour-tools:") == ("pour-tools: Eigen 3.3+ not found: pip install cmeel-eigen "
                                          "(or apt-get install libeigen3-dev) and build again")


def test_a_wheel_build_without_a_compiler_says_what_to_install(checkout_copy, tmp_path):
    r = pip_wheel(checkout_copy / "src", tmp_path, env=dict(os.environ, CC="/nonexistent/cc", CXX="/nonexistent/c++"))
    assert r.returncode != 0 and not list(tmp_path.glob("*.whl"))
    assert one_line(r, "pour-tools:") == ("pour-tools: no C and C++ compiler found: install g++ "
                                          "(apt-get install g++) and build again")
