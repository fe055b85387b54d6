# SPDX-License-Identifier: MIT
"""The flow coefficient at the lip, from the log of the tilt experiment (water, a slow tilt to 90°).

The reference is the sharp-crested weir (docs/simulator.md): a liquid that keeps a level surface sheds,
per metre of lip, q = C_d · (2/3) · √(2g) · H^{3/2}, H the head of the level above the lower lip. The 2D
analogue of the round bucket: the liquid's cross-section A = 4 m / (ρ π w) (the simulator's mass of a fill,
ρ · fill_depth · π w² / 4, over its section w · fill_depth), so q = -dA/dt from the rotating scale. The head
is hydrostatics: the level at which the inner section, tilted by θ, holds A below it, less the lip's
height. C_d is the least-squares ratio of q to (2/3) √(2g) H^{3/2} over the outflow, both sides passed
through one smoothing filter (the scale's conversions are noisy and held between); its uncertainty is the
batch means over consecutive spans of the outflow.
"""
from __future__ import annotations

import numpy as np

from pour.sysid.fit import G0, Estimate, savgol
from pour.sysid.log import LogError, Run

TILT_PHASES = (5, 6)    # up and held (pour/experiment.h): the liquid leaves then
SMOOTH_HALF = 250       # [ticks] the filter's half window: 0.5 s, many conversions and slosh periods
HEAD_MIN = 0.005        # [m] a head below a quarter of a particle spacing is not a flow over the lip
OUTFLOW_MIN_S = 1.0     # [s] of outflow the fit needs
LOST_MIN = 0.2          # the share of the liquid that must leave during the tilt
BATCHES = 8
LEVEL_ITERATIONS = 40   # bisection of the level: 2^-40 of the bucket's height
HEAD_EVERY = 20         # [ticks] the head is solved this often and interpolated (the filter spans 500)


def _section(rig: dict, theta: float) -> np.ndarray:
    """The inner section's corners in the world frame [m], pivot at the origin, tilted by theta (> 0 pours
    towards +x): bottom-left, bottom-right, top-right (the lower lip when theta > 0), top-left."""
    wi, top = 0.5 * rig["bucket_inner_width"], 0.5 * rig["bucket_height"]
    bottom = -top + rig["bucket_wall"]
    p = np.array([[-wi, bottom], [wi, bottom], [wi, top], [-wi, top]])
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack([p[:, 0] * c + p[:, 1] * s, -p[:, 0] * s + p[:, 1] * c])


def area_below(corners: np.ndarray, level: float) -> float:
    """Area of the convex polygon corners below the horizontal line y = level [m²] (clipped, shoelace)."""
    out = []
    for i in range(len(corners)):
        a, b = corners[i], corners[(i + 1) % len(corners)]
        if a[1] <= level:
            out.append(a)
        if (a[1] - level) * (b[1] - level) < 0:
            out.append(a + (b - a) * (level - a[1]) / (b[1] - a[1]))
    if len(out) < 3:
        return 0.0
    q = np.array(out)
    return 0.5 * abs(float(np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(q[:, 1], np.roll(q[:, 0], -1))))


def head(rig: dict, theta: float, area: float) -> float:
    """The head [m] over the lower lip of a level liquid of cross-section area [m²] in the section tilted by
    theta: the level that holds area below it, less the lip's height (< 0: the level is below the lip)."""
    corners = _section(rig, theta)
    lo, hi = float(corners[:, 1].min()), float(corners[:, 1].max())
    if area >= area_below(corners, hi):
        return hi - min(corners[2, 1], corners[3, 1])
    for _ in range(LEVEL_ITERATIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if area_below(corners, mid) < area else (lo, mid)
    return 0.5 * (lo + hi) - min(corners[2, 1], corners[3, 1])


def weir_rate(h: np.ndarray) -> np.ndarray:
    """(2/3) √(2g) H^{3/2} [m²/s per unit C_d], 0 for H <= 0."""
    return (2.0 / 3.0) * np.sqrt(2.0 * G0) * np.clip(h, 0.0, None) ** 1.5


def fit_flow(run: Run, rig: dict) -> tuple[Estimate, dict[str, np.ndarray]]:
    """C_d of the tilt experiment's log with its standard deviation, and the series for a figure. rig: the
    known figures (bucket geometry, liquid_density, encoder_bits, scale_delay_s, dt). LogError when the
    log has no outflow to fit (the tilt never brought the level over the lip)."""
    if run.kind != 2:
        raise LogError("the log is of the identify experiment (bucket empty): the flow coefficient needs the "
                       "tilt experiment's (with water)")
    dt = rig["dt"]
    n = len(run.t)
    theta = run.theta(int(rig["encoder_bits"]))
    # Each conversion is the mean load over scale_delay_s before it: the reading lags the liquid by half that.
    lag = int(round(0.5 * rig["scale_delay_s"] / dt))
    mass = np.concatenate([run.scale_rotating[lag:], np.full(lag, run.scale_rotating[-1])]) * 1e-3  # [kg]
    to_area = 4.0 / (rig["liquid_density"] * np.pi * rig["bucket_inner_width"])  # [m² per kg]
    area = savgol(mass, 0, dt, SMOOTH_HALF) * to_area
    q = -savgol(mass, 1, dt, SMOOTH_HALF) * to_area
    k = np.arange(0, n, HEAD_EVERY)
    th = savgol(theta, 0, dt, SMOOTH_HALF)
    h = np.interp(np.arange(n), k, [head(rig, th[i], area[i]) for i in k])
    x = savgol(weir_rate(h), 0, dt, SMOOTH_HALF)
    edge = np.zeros(n, dtype=bool)
    edge[SMOOTH_HALF:n - SMOOTH_HALF - lag] = True
    use = edge & np.isin(run.action, TILT_PHASES) & (h > HEAD_MIN)
    top = float(np.degrees(theta.max()))
    tilt = np.isin(run.action, TILT_PHASES)
    start, least = 1000 * area[edge & tilt][0] / to_area, 1000 * area[edge & tilt].min() / to_area
    if start - least < LOST_MIN * start:
        raise LogError(f"cannot identify the flow coefficient at the lip: no liquid left the bucket (the rotating "
                       f"scale read {start:.0f} g as the tilt began and at least {least:.0f} g up to "
                       f"{top:.1f} deg): a bucket with water, tilted past its lip")
    if use.sum() * dt < OUTFLOW_MIN_S:
        raise LogError(f"cannot identify the flow coefficient at the lip: the liquid flowed over the lip for "
                       f"{use.sum() * dt:.2f} s (a head above {1000 * HEAD_MIN:.0f} mm; {OUTFLOW_MIN_S:.1f} s needed); "
                       f"the tilt reached {top:.1f} deg with {start:.0f} g in the bucket: tilt further, or fill it")
    xs, qs = x[use], q[use]
    cd = float(xs @ qs / (xs @ xs))
    batch = np.arange(xs.size) * BATCHES // xs.size
    per = [float(xs[batch == i] @ qs[batch == i] / (xs[batch == i] @ xs[batch == i])) for i in range(BATCHES)]
    sigma = float(np.std(per, ddof=1) / np.sqrt(BATCHES))
    est = Estimate(cd, sigma, "-", f"flow coefficient at the lip: q = C_d (2/3) sqrt(2g) H^1.5 "
                                   f"({use.sum() * dt:.1f} s of outflow, head up to {1000 * h[use].max():.0f} mm)")
    series = {"t": run.t - run.t[0], "theta": theta, "area": area, "q": q, "q_model": cd * x, "use": use}
    return est, series


# The simulator's C_d against its fluid_viscosity [1/s]: (value, mean C_d, spread over seeds 1-4), measured
# by `python -m pour.sysid.flowmap` (its output pasted; docs/bench.md tabulates it). The pair viscosity damps
# the particles' agitation, and the liquid then leaves faster: C_d rises with it, monotonically.
CD_MAP = ((0, 0.3245, 0.0096), (1, 0.3832, 0.0109), (2, 0.4072, 0.0202), (3, 0.4427, 0.0091), (5, 0.4942, 0.0171),
          (7, 0.5397, 0.0181), (10, 0.6678, 0.0448), (14, 0.7569, 0.1116), (20, 0.9715, 0.0278))
KEY = "fluid_viscosity"


def key_of(cd: Estimate) -> Estimate:
    """The fluid_viscosity whose C_d (CD_MAP, interpolated) is cd's, with cd's sigma through the map's
    slope; LogError when cd lies outside what the map reaches."""
    v, m = np.array([r[0] for r in CD_MAP]), np.array([r[1] for r in CD_MAP])
    if not m[0] <= cd.value <= m[-1]:
        raise LogError(f"the flow coefficient {cd.value:.3f} is outside what the simulator's {KEY} reaches "
                       f"({m[0]:.3f} at {v[0]:g} .. {m[-1]:.3f} at {v[-1]:g} 1/s): nothing written")
    x = float(np.interp(cd.value, m, v))
    i = int(np.clip(np.searchsorted(m, cd.value), 1, len(m) - 1))
    slope = (v[i] - v[i - 1]) / (m[i] - m[i - 1])
    return Estimate(x, cd.sigma * slope, "1/s", f"the simulator's pair viscosity whose C_d is {cd.value:.3f}")


def cd_of(viscosity: float) -> float:
    """CD_MAP's C_d at fluid_viscosity = viscosity (interpolated)."""
    return float(np.interp(viscosity, [r[0] for r in CD_MAP], [r[1] for r in CD_MAP]))
