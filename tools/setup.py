# SPDX-License-Identifier: MIT
"""Build hook of the pour-tools wheel: it carries the CAN protocol's DBC and the generated Python LCM types
as package data (pour/data/), made at build time from their one source in the checkout (can/pour.dbc,
lcmtypes/pour/*.lcm, through the LCM wheel's lcm-gen), so an installed package needs no checkout. An
editable install reads them from the checkout and its build tree instead (pour.paths). The wheel also
carries _pour_gymnasium.pth, the start-up hook that registers the Gymnasium ids (_pour_gymnasium.py)."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from pour import paths  # noqa: E402  (stdlib only: the names of the data files and folders)

GYM_HOOK_PTH = "_pour_gymnasium.pth"


def lcm_gen() -> str:
    """lcm-gen of the LCM wheel (under its site-packages prefix), else one on PATH."""
    try:
        import lcm
        exe = Path(lcm.__file__).resolve().parents[1] / "bin" / "lcm-gen"
        if exe.is_file():
            return str(exe)
    except ImportError:
        pass
    found = shutil.which("lcm-gen")
    if not found:
        raise SystemExit("pour-tools: building the wheel needs lcm-gen (pip install lcm) for the LCM types")
    return found


class BuildWithData(build_py):
    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        # site runs a .pth only from site-packages itself, so it sits beside the packages, not in one.
        shutil.copyfile(HERE / GYM_HOOK_PTH, Path(self.build_lib) / GYM_HOOK_PTH)
        data = Path(self.build_lib) / "pour" / paths.PACKAGE_DATA.name
        data.mkdir(parents=True, exist_ok=True)
        for name, source in paths.DATA_SOURCES.items():
            src = ROOT / source
            if not src.is_file():
                raise SystemExit(f"pour-tools: {src} not found: build the wheel from a checkout")
            shutil.copyfile(src, data / name)
        lcm_files = sorted(str(p) for p in (ROOT / "lcmtypes" / "pour").glob("*.lcm"))
        if not lcm_files:
            raise SystemExit(f"pour-tools: no LCM types in {ROOT / 'lcmtypes' / 'pour'}: build from a checkout")
        out = data / paths.LCMTYPES_DIR
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir()
        subprocess.run([lcm_gen(), "-p", "--ppath", str(out), "--package-prefix", "pour_lcm", *lcm_files],
                       check=True, stdout=subprocess.DEVNULL)


setup(cmdclass={"build_py": BuildWithData})
