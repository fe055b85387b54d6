# SPDX-License-Identifier: MIT
"""The simulator's flow coefficient at the lip against its fluid_viscosity: host_sim's tilt experiment at
each value and seed, C_d fitted from each log as pour-sysid fits a rig's (pour.sysid.flow), the mean and
the spread over the seeds printed. flow.CD_MAP is this program's output with its defaults:
`python -m pour.sysid.flowmap`."""
from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Sequence

import numpy as np

from pour import cli, paths
from pour.sim import poursim
from pour.sysid import flow
from pour.sysid import log as slog

PROG = "python -m pour.sysid.flowmap"
VALUES = (0.0, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 14.0, 20.0)
SEEDS = (1, 2, 3, 4)


def tilt_cd(host_sim: Path, viscosity: float, seed: int, work: Path) -> float:
    """C_d of one tilt experiment in the simulator with fluid_viscosity = viscosity."""
    log = work / f"tilt_{viscosity:g}_{seed}.log"
    r = subprocess.run([str(host_sim), "--experiment", "tilt", "--candump", str(log), "--seed", str(seed),
                        "--set", f"fluid_viscosity={viscosity:g}"], capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        raise RuntimeError(f"host_sim tilt at fluid_viscosity {viscosity:g}, seed {seed}: "
                           f"{r.stdout[-300:]}{r.stderr[-300:]}")
    base = poursim.default_config()
    base["fluid_viscosity"] = viscosity
    return flow.fit_flow(slog.read(log, 0), base)[0].value


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    ap.add_argument("--values", type=float, nargs="+", default=list(VALUES), help="fluid_viscosity values [1/s]")
    ap.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS), help="seeds of each value")
    ap.add_argument("--build-dir", help="the build holding bin/host_sim (default build/host)")
    a = ap.parse_args(argv)
    host_sim = paths.binary("host_sim", a.build_dir)
    if host_sim is None:
        print(f"{PROG}: error: host_sim not found: build it (cmake --build --preset host)", file=sys.stderr)
        return 2
    if sorted(a.values) != a.values or min(a.values) < 0:
        print(f"{PROG}: error: --values must be >= 0 and increasing", file=sys.stderr)
        return 2
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for v in a.values:
            cd = np.array([tilt_cd(host_sim, v, s, Path(d)) for s in a.seeds])
            rows.append((v, float(cd.mean()), float(cd.std(ddof=1)) if cd.size > 1 else float("nan")))
            print(f"fluid_viscosity {v:6.2f}: C_d {rows[-1][1]:.4f}, spread over {cd.size} seeds {rows[-1][2]:.4f} "
                  f"({', '.join(f'{c:.3f}' for c in cd)})", flush=True)
    print("CD_MAP = (" + ", ".join(f"({v:g}, {m:.4f}, {s:.4f})" for v, m, s in rows) + ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
