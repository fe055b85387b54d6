# SPDX-License-Identifier: MIT
"""pour-sysid: fit a rig file from the log of the controller's identify experiment (bucket empty).

LOG is a candump -L log as pour-bench identify records it on a rig, or as host_sim --experiment identify
writes it; --tilt adds the tilt experiment's log (with water), which weighs the fill (fill_depth: a tofu
line's batch volume is the installation's, and pour-train --rig centres the fill range on it) and gives the
flow coefficient at the lip and the simulator's fluid_viscosity that reproduces it. The figures the log
cannot give (the bucket's mass and drawing, the gear ratio, the encoder's bits, the scale's resolution, the
liquid's density) come from --base (a rig file or simulator config; default: the simulator's defaults). The
rig file gets the fitted keys with their standard deviations; --png draws the measured and the fitted
responses over each other.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from pour import atomic, cli
from pour.libpoursim import SimError
from pour.sim import poursim
from pour.sysid import fit as sf
from pour.sysid import flow
from pour.sysid import log as slog
from pour.sysid import rig as srig

PROG = "pour-sysid"
EPILOG = ("Exit status (the same meanings in every pour program): 0 done; 1 a log that cannot be fitted "
          "(truncated, of another node, with gaps, a refused or cut-short experiment, a parameter it does not "
          "excite, a --tilt log without outflow over the lip), no simulator library, a write that failed; 2 bad "
          "input (the command line, the base rig file, a log that cannot be read).")

NO_FILL = "fill_depth: not identified (no --tilt log with water): training keeps its config's fill and range"


def parser():
    ap = cli.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0], epilog=EPILOG)
    ap.add_argument("log", type=Path, help="candump -L log of the identify experiment")
    ap.add_argument("--out", type=Path, required=True, help="the rig file to write (.toml, or .cfg for host_sim)")
    ap.add_argument("--node", type=int, default=0, help="the controller's node id (default 0)")
    ap.add_argument("--base", type=Path, help="rig file or simulator config with the rig's known figures")
    ap.add_argument("--tilt", type=Path, metavar="LOG", help="candump -L log of the tilt experiment (the bucket "
                    "filled as for a pour): the fill (fill_depth) weighed, and the flow coefficient at the lip; "
                    "without it the fill is not identified and the rig file leaves it out")
    ap.add_argument("--png", type=Path, help="measured vs fitted responses")
    ap.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    return ap


def figure(fit: sf.Fit, path: Path, tilt: dict | None = None) -> None:
    """Three panels: the acceleration against the fitted model's, the angle against the fitted model
    run from the measured state every 0.5 s, and the rotating scale's readings against the fitted cell's;
    with tilt (flow.fit_flow's series) a fourth: the outflow over the lip against the fitted weir's."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    s = fit.series
    t, use = s["t"], s["use"]
    fig, ax = plt.subplots(4 if tilt else 3, 1, figsize=(10, 10.5 if tilt else 8))
    for a in ax[1:3]:
        a.sharex(ax[0])
    ax[0].plot(t, s["accel"], lw=0.8, label="measured (filtered)")
    ax[0].plot(t[use], s["accel_model"][use], ".", ms=1, label="the fitted model's, from the commanded torque")
    ax[0].set_ylabel("θ̈ [rad/s²]")
    ax[1].plot(t, np.degrees(s["theta"]), lw=0.8, label="measured")
    ax[1].plot(t, np.degrees(s["theta_sim"]), lw=0.8, label="simulated: the fit, from the measured state every 0.5 s")
    ax[1].set_ylabel("θ [deg]")
    ax[2].plot(t[s["conv"]], s["reading"], ".", ms=2, label="rotating scale, measured")
    ax[2].plot(t[s["conv"]], s["reading_model"], lw=0.8, label="the fitted cell (inertial load, delay)")
    ax[2].set_ylabel("scale [g]")
    ax[2].set_xlabel("t [s] (identify)")
    if tilt:
        u = tilt["use"]
        ax[3].plot(tilt["t"], 1e3 * tilt["q"], lw=0.8, label="outflow, from the rotating scale (tilt)")
        ax[3].plot(tilt["t"][u], 1e3 * tilt["q_model"][u], ".", ms=1,
                   label="C_d (2/3) sqrt(2g) H^1.5, H by hydrostatics")
        ax[3].set_ylabel("q [L/s per m of lip, 2D]")
        ax[3].set_xlabel("t [s] (tilt)")
    for a in ax:
        a.legend(loc="upper right", fontsize=8)
        a.grid(alpha=0.3)
    fig.suptitle("pour-sysid: the identify experiment" + (" and the tilt" if tilt else "") + ", measured and fitted")
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
    except SimError as e:  # the simulator library holds the rig's defaults
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    try:
        run = slog.read(a.log, a.node)
        fit = sf.fit_identify(run, base)
        e = fit.estimates
        if a.tilt is not None:
            tilt_run = slog.read(a.tilt, a.node)
            e["fill_depth"] = sf.fit_fill(tilt_run, base)
            # The tilt's scale lags by the delay the identify log just measured.
            cd, tilt = flow.fit_flow(tilt_run, {**base, "scale_delay_s": e["scale_delay_s"].value})
            e["flow_coefficient"] = cd
            e[flow.KEY] = flow.key_of(cd)
    except slog.LogUnreadable as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    except (slog.LogError, SimError) as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 1
    fitted = srig.Rig({k: e[k].value for k in srig.FITTED if k in e},
                      {k: e[k].sigma for k in srig.FITTED if k in e and np.isfinite(e[k].sigma)})
    fitted.values["friction_viscous"] = max(0.0, fitted.values["friction_viscous"])
    flagged = sf.check_trust(fit)
    header = [f"Fitted by {PROG} {cli.version()} from {a.log.name}" + (f" and {a.tilt.name}" if a.tilt else "")
              + f" (node {a.node}): do not edit by hand.",
              "The identify experiment (bucket empty)" + (", the tilt (with water)" if a.tilt else "")
              + "; docs/bench.md says what each figure means."]
    header += [f"{k}: {v.value:.6g} +- {v.sigma:.3g} {v.unit}: {v.meaning}" for k, v in e.items()]
    if flagged:
        header.append("uncertain beyond 5 %: " + ", ".join(flagged))
    if "fill_depth" not in e:
        header.append(NO_FILL)
    try:
        srig.save(a.out, fitted, header)
        if a.png is not None:
            fit.series["theta_sim"] = simulate(run, fit, base)
            figure(fit, a.png, tilt if a.tilt is not None else None)
    except OSError as err:
        print(f"{PROG}: error: {err.filename or a.out}: cannot write ({err.strerror})", file=sys.stderr)
        return 1
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
