# SPDX-License-Identifier: MIT
"""pour-sysid: fit a rig file from the log of the controller's identify experiment (bucket empty).

With --tilt, the log of the tilt experiment (with water) weighs the fill: a tofu line's batch volume is the
installation's, so the rig file carries it (fill_depth) and pour-train --rig centres the fill range on it.

LOG is a candump -L log as pour-bench identify records it on a rig, or as host_sim --experiment identify
writes it. The figures the log cannot give (the bucket's mass and drawing, the gear ratio, the encoder's
bits, the scale's resolution) come from --base (a rig file or simulator config; default: the simulator's
defaults). The rig file gets the fitted keys with their standard deviations; --png draws the measured and
the fitted responses over each other.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from pour import atomic, cli
from pour.sim import poursim
from pour.sysid import fit as sf
from pour.sysid import log as slog
from pour.sysid import rig as srig

PROG = "pour-sysid"
EPILOG = ("Exit status (the same meanings in every pour program): 0 done; 1 a log that cannot be fitted "
          "(truncated, of another node, with gaps, a refused or cut-short experiment, a parameter it does not "
          "excite); 2 bad input (the command line, the base rig file).")

NO_FILL = "fill_depth: not identified (no --tilt log with water): training keeps its config's fill and range"


def parser():
    ap = cli.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0], epilog=EPILOG)
    ap.add_argument("log", type=Path, help="candump -L log of the identify experiment")
    ap.add_argument("--out", type=Path, required=True, help="the rig file to write (.toml, or .cfg for host_sim)")
    ap.add_argument("--node", type=int, default=0, help="the controller's node id (default 0)")
    ap.add_argument("--base", type=Path, help="rig file or simulator config with the rig's known figures")
    ap.add_argument("--tilt", type=Path, metavar="LOG", help="candump -L log of the tilt experiment (the bucket "
                    "filled as for a pour): the fill (fill_depth) is weighed from it; without it the fill is not "
                    "identified and the rig file leaves it out")
    ap.add_argument("--png", type=Path, help="measured vs fitted responses")
    ap.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    return ap


def figure(fit: sf.Fit, path: Path) -> None:
    """Three panels: the acceleration against the fitted model's, the angle against the fitted model
    run from the measured state every 0.5 s, and the rotating scale's readings against the fitted cell's."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    s = fit.series
    t, use = s["t"], s["use"]
    fig, ax = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    ax[0].plot(t, s["accel"], lw=0.8, label="measured (filtered)")
    ax[0].plot(t[use], s["accel_model"][use], ".", ms=1, label="the fitted model's, from the commanded torque")
    ax[0].set_ylabel("θ̈ [rad/s²]")
    ax[1].plot(t, np.degrees(s["theta"]), lw=0.8, label="measured")
    ax[1].plot(t, np.degrees(s["theta_sim"]), lw=0.8, label="simulated: the fit, from the measured state every 0.5 s")
    ax[1].set_ylabel("θ [deg]")
    ax[2].plot(t[s["conv"]], s["reading"], ".", ms=2, label="rotating scale, measured")
    ax[2].plot(t[s["conv"]], s["reading_model"], lw=0.8, label="the fitted cell (inertial load, delay)")
    ax[2].set_ylabel("scale [g]")
    ax[2].set_xlabel("t [s]")
    for a in ax:
        a.legend(loc="upper right", fontsize=8)
        a.grid(alpha=0.3)
    fig.suptitle("pour-sysid: the identify experiment, measured and fitted")
    fig.tight_layout()
    with atomic.atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)


def simulate(run: slog.Run, fit: sf.Fit, rig: dict) -> np.ndarray:
    """The fitted axis driven by the commanded torque, restarted from the measured state every 0.5 s
    (the run is in closed loop: over longer spans any model drifts from the loop that held it)."""
    e = fit.estimates
    dt, n = rig["dt"], len(run.t)
    J, s, Fc, b = e["inertia"].value, e["torque_scale"].value, e["friction_coulomb"].value, e["friction_viscous"].value
    G = sf.bucket_arm_and_inertia(rig)[0] * sf.G0
    L = int(e["command_latency_ticks"].value)
    theta = fit.series["theta"]
    omega = sf.savgol(theta, 1, dt)
    out = np.empty(n)
    th = om = 0.0
    for k in range(n):
        if k % 500 == 0:
            th, om = theta[k], omega[k]
        out[k] = th
        drive = s * (run.torque[k - L] if k >= L else 0.0) - b * om - G * np.sin(th)
        if abs(om) < 1e-3 and abs(drive) <= Fc:
            om = 0.0  # held by friction
        else:
            om += dt * (drive - Fc * np.sign(om if om != 0.0 else drive)) / J
        th += dt * om
    return out


def main(argv: list[str] | None = None) -> int:
    a = parser().parse_args(argv)
    try:
        for p, what in ((a.out, "--out"), (a.png, "--png")):
            if p is not None:
                atomic.check_output_path(p, what)
        if a.out.suffix not in (".toml", ".cfg"):
            raise ValueError(f"--out {a.out}: a .toml or .cfg file name")
        if not 0 <= a.node <= 63:
            raise ValueError(f"--node {a.node} outside 0..63")
        base = poursim.default_config()
        if a.base is not None:
            base.update(srig.load(a.base).values)
    except (ValueError, srig.RigError) as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    try:
        run = slog.read(a.log, a.node)
        fit = sf.fit_identify(run, base)
        if a.tilt is not None:
            fit.estimates["fill_depth"] = sf.fit_fill(slog.read(a.tilt, a.node), base)
    except slog.LogError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    e = fit.estimates
    keys = [k for k in srig.FITTED if k in e]
    fitted = srig.Rig({k: e[k].value for k in keys}, {k: e[k].sigma for k in keys if np.isfinite(e[k].sigma)})
    fitted.values["friction_viscous"] = max(0.0, fitted.values["friction_viscous"])
    flagged = sf.check_trust(fit)
    header = [f"Fitted by {PROG} {cli.version()} from {a.log.name} (node {a.node}): do not edit by hand.",
              "The identify experiment (bucket empty); docs/bench.md says what each figure means."]
    header += [f"{k}: {v.value:.6g} +- {v.sigma:.3g} {v.unit}: {v.meaning}" for k, v in e.items()]
    if flagged:
        header.append("uncertain beyond 5 %: " + ", ".join(flagged))
    if "fill_depth" not in e:
        header.append(NO_FILL)
    srig.save(a.out, fitted, header)
    if a.png is not None:
        fit.series["theta_sim"] = simulate(run, fit, base)
        figure(fit, a.png)
    if a.json:
        print(json.dumps({k: {"value": v.value, "sigma": v.sigma, "unit": v.unit} for k, v in e.items()}))
    else:
        for k, v in e.items():
            print(f"{k:22s} {v.value:12.6g} +- {v.sigma:<10.3g} {v.unit:18s} {v.meaning}")
        if "fill_depth" not in e:
            print(NO_FILL)
        print(f"{PROG}: rig file {a.out}" + (f", figure {a.png}" if a.png else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
