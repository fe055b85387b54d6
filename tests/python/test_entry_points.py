# SPDX-License-Identifier: MIT
"""Every pour-* console script as a plain `pip install ./tools` (no extras) leaves it: --help exits 0 with no
traceback when the optional extras (gym, ray, sb3) are absent, and a command that needs one says so in one
line naming the extra. The extras are hidden from the project's venv by a finder in front of sys.meta_path
that refuses them as an uninstalled package would (ModuleNotFoundError)."""
import os
import subprocess
import sys
from importlib import metadata

import pytest

from pour import cli

EXTRAS = ("gymnasium", "ray", "stable_baselines3", "torch")

# argv[1]: the console script's name; argv[2:]: its arguments. The entry point is loaded and called as its
# script would, with the extras' top-level modules refused.
RUN_WITHOUT_EXTRAS = r"""
import sys
from importlib import metadata

HIDDEN = set(sys.argv[1].split(","))


class Hide:
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name.split(".")[0] in HIDDEN:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, Hide)
(ep,) = [e for e in metadata.entry_points(group="console_scripts") if e.name == sys.argv[2]]
sys.argv = sys.argv[2:]
sys.exit(ep.load()())
"""


def scripts() -> list[str]:
    eps = metadata.distribution("pour-tools").entry_points
    return sorted(e.name for e in eps if e.group == "console_scripts")


def run_without_extras(name: str, *args, timeout: int = 120) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "POUR_SIM_LIB"}
    return subprocess.run([sys.executable, "-c", RUN_WITHOUT_EXTRAS, ",".join(EXTRAS), name, *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, env=env)


def test_every_console_script_is_listed():
    names = scripts()
    assert len(names) >= 17 and {"pour-results", "pour-sweep", "pour-train", "pour-bench"} <= set(names)


@pytest.mark.parametrize("name", scripts())
def test_help_exits_0_without_the_extras(name):
    r = run_without_extras(name, "--help")
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr and "usage:" in r.stdout and name in r.stdout, r.stderr


def test_the_hiding_finder_hides(tmp_path):
    """The check itself: a program that imports gymnasium at the top fails under it as in a plain install."""
    r = subprocess.run([sys.executable, "-c", RUN_WITHOUT_EXTRAS.replace(
        "sys.meta_path.insert(0, Hide)", "sys.meta_path.insert(0, Hide); import gymnasium"), "gymnasium",
        "pour-train", "--help"], capture_output=True, text=True, timeout=60)
    assert r.returncode != 0 and "No module named 'gymnasium'" in r.stderr


def test_ray_executor_without_ray_is_one_line_naming_the_extra(source_dir, tmp_path):
    r = run_without_extras("pour-train", source_dir / "configs" / "train" / "toy.toml", "-o", tmp_path / "run",
                           "--iterations", "1", "--executor", "ray", "--quiet")
    assert r.returncode != 0 and "Traceback" not in r.stderr, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert "ray" in line and "./tools[ray]" in line, line


def test_require_names_the_extra_and_exits_1(monkeypatch):
    monkeypatch.setattr(sys, "argv", ["pour-results"])
    with pytest.raises(SystemExit) as e:
        cli.require("pour_no_such_module_xyz", "gym")
    assert isinstance(e.value, cli.MissingExtra) and e.value.code == (
        "pour-results: pour_no_such_module_xyz is not installed: it comes with the gym extra "
        "(pip install './tools[gym]')")


def test_require_lets_an_import_error_from_inside_an_installed_module_through(tmp_path, monkeypatch):
    (tmp_path / "pour_broken_mod.py").write_text("import pour_missing_dependency_xyz\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ModuleNotFoundError, match="pour_missing_dependency_xyz"):
        cli.require("pour_broken_mod", "gym")
