# SPDX-License-Identifier: MIT
"""The fit of the identify experiment (bucket empty): the axis' equation of motion and the pivot cell.

The axis, at the output, with the command of L ticks before acting now:

    J θ̈ = s τ(t - L) - F_c sgn θ̇ - b θ̇ - G sin θ

τ is what the controller commanded (its Torque frames), s the torque scale (what the drive delivers per
N m commanded), G = m g d the empty bucket's gravity arm. Only ratios to J show in the motion, so the
equation is fitted as θ̈ = (s/J) τ(t - L) - (F_c/J) sgn θ̇ - (b/J) θ̇ - (G/J) sin θ by least squares, for
each latency L, and G, known from the bucket's mass and drawing (the rig file's bucket_mass and geometry),
sets J. θ̈ is the encoder angle's second difference and θ̇ its centred first difference (the backward one
shares a count's quantisation error with θ̈, negatively correlated, which reads as viscous friction: +3 %
on the default rig's 17 bits), and every term passes one smoothing filter (Savitzky-Golay), under which
the equation stays exact. Samples near standstill (stiction: the friction is anything up to F_c there)
are left out. b is fitted where the bucket keeps moving one way (the chirp and the sweep): in the steps,
which reverse every 250 ms, b θ̇ is about 1 % of F_c and their b alone reads 13 % high even with a
24-bit encoder; the other figures are fitted on every phase with that b.

The pivot's load cell carries the bucket's inertial load m a_y = m d (θ̈ sin θ + θ̇² cos θ) [g]; each of
its conversions reports the mean load over the scale's delay before it. The delay is the span that best
explains the readings; the noise is their spread while the bucket is at rest, beyond the cell's resolution.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pour.sysid.log import LogError, Run

G0 = 9.81            # [m/s²], as the simulator's
SG_HALF = 15         # the filter's half window [ticks]: 31 ms, flat to beyond the chirp's 6 Hz
SG_ORDER = 3
LATENCY_MAX = 12     # [ticks] searched
OMEGA_MIN = 0.05     # [rad/s] below it the axis may stick: left out
DELAY_MAX = 400      # [ticks] of scale delay searched
FIT_PHASES = (2, 3, 10)  # steps, chirp and sweep: the excitation (pour/experiment.h)
VISCOUS_PHASES = (3, 10)  # chirp and sweep: sustained motion one way, where b θ̇ is told from F_c
REL_SIGMA_MAX = 0.25  # a parameter known worse than this is not identified by the log
VISCOUS_SIGMA_MAX = 0.05  # viscous friction known worse than this (batch means) is not identified
BATCHES = 8          # batch means for the reported uncertainties
REST_TICKS_MIN = 250  # [ticks] at rest (the filter settled) for the scale's noise: ~20 conversions
TRUST_SIGMA_MAX = 0.05


@dataclass
class Estimate:
    value: float
    sigma: float
    unit: str
    meaning: str


@dataclass
class Fit:
    estimates: dict[str, Estimate] = field(default_factory=dict)
    latency_rss: dict[int, float] = field(default_factory=dict)   # L -> residual sum of squares
    delay_rss: np.ndarray | None = None
    series: dict[str, np.ndarray] = field(default_factory=dict)    # for the figure


def savgol(x: np.ndarray, deriv: int, dt: float, half: int = SG_HALF) -> np.ndarray:
    """x's local cubic fit over ±half ticks, or its first or second derivative (ends: edge values)."""
    k = np.arange(-half, half + 1, dtype=float)
    V = np.vander(k, SG_ORDER + 1, increasing=True)
    c = np.linalg.pinv(V)[deriv] * float(np.prod(range(1, deriv + 1)) if deriv else 1.0) / dt ** deriv
    xp = np.concatenate([np.full(half, x[0]), x, np.full(half, x[-1])])
    return np.convolve(xp, c[::-1], mode="valid")


def bucket_arm_and_inertia(rig: dict) -> tuple[float, float]:
    """The empty U's m·d [kg m] (its centre of mass below the pivot) and its inertia about the pivot
    [kg m²], from the rig's bucket_mass and geometry: the mass spread over the three walls by area."""
    wi, t, hh = 0.5 * rig["bucket_inner_width"], rig["bucket_wall"], 0.5 * rig["bucket_height"]
    boxes = [(2 * wi + 2 * t, t, 0.0, -hh + 0.5 * t), (t, 2 * hh, -wi - 0.5 * t, 0.0), (t, 2 * hh, wi + 0.5 * t, 0.0)]
    area = sum(w * h for w, h, _, _ in boxes)
    inertia = md = 0.0
    for w, h, x, y in boxes:
        m = rig["bucket_mass"] * w * h / area
        inertia += m * ((w * w + h * h) / 12.0 + x * x + y * y)
        md -= m * y
    return md, inertia


def _lsq(X: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Least squares: coefficients, their covariance and the RSS. The residuals of filtered signals are
    correlated over the filter's window: the covariance counts one independent sample per window (a
    conservative bound, used to tell a parameter the log does not excite; the figures' reported
    uncertainties are _batch_sigma's)."""
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ coef
    rss = float(r @ r)
    n, p = X.shape
    var = rss / max(1, n - p)
    cov = var * np.linalg.pinv(X.T @ X) * (2 * SG_HALF + 1)
    return coef, cov, rss


def _batch_sigma(X: np.ndarray, y: np.ndarray, coef: np.ndarray, figures, free: bool, k: int = BATCHES) -> np.ndarray:
    """Standard deviations of figures(coef) by batch means: the samples dealt round-robin, in runs of two
    filter windows (longer than the residuals' correlation), into k batches each fitted on its own; the
    spread of the k fits over sqrt(k). free: the viscous ratio was fitted (else it stays coef's)."""
    run = 2 * (2 * SG_HALF + 1)
    batch = (np.arange(len(y)) // run) % k
    keep = [0, 1, 2, 3] if free else [0, 1, 3]
    out = []
    for i in range(k):
        m = batch == i
        yi = y[m] - (0.0 if free else coef[2] * X[m, 2])
        c, *_ = np.linalg.lstsq(X[m][:, keep], yi, rcond=None)
        full = coef.copy()
        full[keep] = c
        out.append(figures(full))
    return np.std(np.array(out), axis=0, ddof=1) / np.sqrt(k)


def fit_identify(run: Run, rig: dict) -> Fit:
    """Every figure of the identify experiment's log with its standard deviation. rig: the known figures
    (bucket_mass, bucket geometry, gear_ratio, encoder_bits, scale_resolution_g, dt)."""
    if run.kind != 1:
        raise LogError("the log is of the tilt experiment (with water): pour-sysid fits the identify one "
                       "(bucket empty), which excites the drive's parameters")
    dt = rig["dt"]
    theta = run.theta(int(rig["encoder_bits"]))
    n = len(theta)
    # The physics' own differences (a semi-implicit step: ω_k = (θ_k - θ_k-1)/dt, the tick's acceleration
    # the second difference), then one smoothing filter for every term: the equation stays exact under it.
    accel = np.zeros(n)
    accel[1:-1] = (theta[2:] - 2 * theta[1:-1] + theta[:-2]) / dt ** 2
    th = savgol(theta, 0, dt)
    om = savgol(np.diff(theta, prepend=theta[0]) / dt, 0, dt)
    al = savgol(accel, 0, dt)
    sgn = savgol(np.sign(om), 0, dt)
    sin = savgol(np.sin(th), 0, dt)
    edge = np.zeros(n, dtype=bool)
    edge[SG_HALF + LATENCY_MAX:n - SG_HALF] = True
    # Moving one way over the whole window: the Coulomb term is then exactly ±F_c.
    moving = np.abs(om) > OMEGA_MIN
    win = np.convolve(moving.astype(float), np.ones(2 * SG_HALF + 1), mode="same") >= 2 * SG_HALF + 1
    use = edge & win & np.isin(run.action, FIT_PHASES)
    if use.sum() < 200:
        raise LogError("cannot identify inertia, friction or torque scale: the bucket hardly moved "
                       f"({int(use.sum())} usable ticks of steps, chirp and sweep): the experiment did not excite them")
    fit = Fit()
    md, j_bucket = bucket_arm_and_inertia(rig)
    g_known = md * G0
    # The acceleration is the dependent variable: it carries the encoder's quantisation noise, which in a
    # regressor would bias the inertia low. α = (s/J) τ(t - L) - (F_c/J) sgn θ̇ - (b/J) θ̇ - (G/J) sin θ.
    y = al[use]
    # (θ_k+1 - θ_k-1) / 2dt = the step's ω_k + θ̈ dt / 2: b dt / 2 joins J, 2e-4 of it.
    om_c = np.zeros(n)
    om_c[1:-1] = (theta[2:] - theta[:-2]) / (2 * dt)
    om_c = savgol(om_c, 0, dt)
    rest = np.column_stack([-sgn, -om_c, -sin])[use]
    def shifted(lat: int) -> np.ndarray:
        return savgol(np.concatenate([np.zeros(lat), run.torque[:n - lat]]), 0, dt)
    for lat in range(0, LATENCY_MAX + 1):
        fit.latency_rss[lat] = _lsq(np.column_stack([shifted(lat)[use], rest]), y)[2]
    lat = min(fit.latency_rss, key=fit.latency_rss.get)
    tau = shifted(lat)
    X = np.column_stack([tau[use], rest])
    coef, cov, rss = _lsq(X, y)
    names = ["torque_scale", "friction_coulomb", "friction_viscous", "inertia"]
    rel = np.sqrt(np.diag(cov)) / np.maximum(np.abs(coef), 1e-12)
    weak = [names[i] for i in (0, 1, 3) if rel[i] > REL_SIGMA_MAX or coef[i] <= 0]
    if weak:
        raise LogError("cannot identify " + ", ".join(weak) + ": the experiment did not excite "
                       + ("it" if len(weak) == 1 else "them") + " (relative uncertainty "
                       + ", ".join(f"{rel[names.index(w)]:.0%}" for w in weak) + ")")
    # J = G / (G/J); every other figure is J times its ratio.
    def figures(c: np.ndarray) -> np.ndarray:
        j = g_known / c[3]
        return np.array([j * c[0], j * c[1], j * c[2], j])
    # b from the phases of sustained motion, its uncertainty by the batch means (the conservative bound above
    # is for the figures the fit cannot do without).
    v = np.isin(run.action[use], VISCOUS_PHASES)
    viscous_fitted = False
    if v.sum() >= 200:
        cv = _lsq(X[v], y[v])[0]
        b_free, sb_free = figures(cv)[2], _batch_sigma(X[v], y[v], cv, figures, free=True)[2]
        viscous_fitted = b_free > 0 and sb_free <= VISCOUS_SIGMA_MAX * b_free
    # Otherwise b θ̇, a few % of F_c at the experiment's speeds, looks like F_c: b is the base rig's, and F_c
    # is what friction is left beyond it (rather than F_c taking b's share).
    b, sb = (b_free, sb_free) if viscous_fitted else (rig["friction_viscous"], float("nan"))
    sub = _lsq(X[:, [0, 1, 3]], y - b * coef[3] / g_known * X[:, 2])[0]
    coef = np.array([sub[0], sub[1], b * coef[3] / g_known, sub[2]])
    s, Fc, _, J = figures(coef)
    s_sigma, sFc, _, sJ = _batch_sigma(X, y, coef, figures, free=False)
    N2 = rig["gear_ratio"] ** 2
    est = fit.estimates
    est["torque_scale"] = Estimate(s, s_sigma, "-", "delivered / commanded torque (the torque constant's error)")
    est["inertia"] = Estimate(J, sJ, "kg m^2", "the empty bucket and the reflected rotor, at the output")
    est["motor_rotor_inertia"] = Estimate((J - j_bucket) / N2, sJ / N2, "kg m^2 at the motor",
                                          f"(J - the bucket's {j_bucket:.5f}) / gear_ratio^2")
    est["friction_coulomb"] = Estimate(Fc, sFc, "N m", "Coulomb friction at the output")
    est["friction_viscous"] = Estimate(b, sb, "N m s/rad", "viscous friction at the output" + (
        "" if viscous_fitted else ": not identified (b θ̇ too small beside F_c at these speeds), the base rig's kept"))
    ranked = sorted(fit.latency_rss.values())
    est["command_latency_ticks"] = Estimate(float(lat), 0.0, "ticks",
                                            f"a command acts this many ticks later (the next best latency "
                                            f"leaves {ranked[1] / ranked[0]:.2f}x the residual)")
    fit.series.update(t=run.t - run.t[0], theta=theta, accel=al, accel_model=np.column_stack([tau, -sgn, -om, -sin]) @ coef,
                      use=use)
    _fit_scale(run, rig, th, om, al, md, fit)
    return fit


def _fit_scale(run: Run, rig: dict, th: np.ndarray, om: np.ndarray, al: np.ndarray, md: float, fit: Fit) -> None:
    """The pivot cell's delay (a box over the load before each conversion) and noise."""
    dt = rig["dt"]
    load = np.sin(th) * al + np.cos(th) * om ** 2   # a_y / d [1/s²]
    reading = run.scale_rotating
    conv = np.flatnonzero(np.diff(reading) != 0) + 1  # a conversion that changed the reading
    conv = conv[(conv > DELAY_MAX + SG_HALF) & (conv < len(reading) - SG_HALF)
                & np.isin(run.action[conv], FIT_PHASES)]
    if conv.size < 50:
        raise LogError("cannot identify scale_delay_s: the rotating scale's reading hardly changed "
                       f"({conv.size} conversions during the excitation)")
    csum = np.concatenate([[0.0], np.cumsum(load)])
    def box(D: int) -> np.ndarray:
        return (csum[conv + 1] - csum[conv + 1 - D]) / D
    y = reading[conv]
    rss = np.full(DELAY_MAX + 1, np.inf)
    for D in range(1, DELAY_MAX + 1):
        X = np.column_stack([box(D), np.ones(conv.size)])
        coef, *_ = np.linalg.lstsq(X, y, rcond=None)
        r = y - X @ coef
        rss[D] = r @ r
    D = int(np.argmin(rss))
    X = np.column_stack([box(D), np.ones(conv.size)])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    var = rss[D] / (conv.size - 2)
    # Uncertainty of the span from the residual's curvature about its minimum (a parabola through 3 points).
    lo, hi = max(1, D - 3), min(DELAY_MAX, D + 3)
    curv = (rss[hi] - 2 * rss[D] + rss[lo]) / (((hi - lo) / 2) ** 2) if hi > lo else 0.0
    sD = float(np.sqrt(2 * var / curv)) if curv > 0 else float("inf")
    res = rig["scale_resolution_g"]
    # The noise where the bucket is at rest (held after the end, still before it breaks away): the load is
    # constant there, so the readings' spread is the cell's own; the fit's residual also holds its misfit.
    still = np.abs(om) < OMEGA_MIN / 10
    quiet = np.convolve(still.astype(float), np.ones(DELAY_MAX), mode="full")[:len(still)] >= DELAY_MAX
    held = reading[quiet]
    if held.size >= REST_TICKS_MIN:
        # Every tick repeats the latest conversion: the ticks' spread weighs each conversion alike.
        noise = float(np.sqrt(max(0.0, float(np.var(held, ddof=1)) - res * res / 12.0)))
        n_rest = held.size * rig["scale_rate_hz"] * dt
    else:
        noise = float(np.sqrt(max(0.0, var - res * res / 12.0)))
        n_rest = conv.size
    est = fit.estimates
    est["scale_delay_s"] = Estimate(D * dt, sD * dt, "s", "the load cell's filter: a mean over this span")
    est["scale_noise_g"] = Estimate(noise, noise / np.sqrt(2 * max(1, n_rest - 2)), "g",
                                    "a conversion's noise, beyond the resolution's (at rest)")
    est["bucket_arm_check"] = Estimate(coef[0] * G0 / 1000.0, 0.0, "kg m",
                                       f"m d as the scale weighs it (the rig file's bucket: {md:.4f})")
    fit.delay_rss = rss
    fit.series.update(conv=conv, reading=y, reading_model=X @ coef)


def check_trust(fit: Fit) -> list[str]:
    """Names of the rig file's figures whose relative uncertainty exceeds TRUST_SIGMA_MAX (they are written,
    and flagged)."""
    return [k for k, e in fit.estimates.items() if e.value and e.sigma / abs(e.value) > TRUST_SIGMA_MAX]


FILL_PHASE = 5           # tilt: up at the tilt speed (pour/experiment.h)
FILL_SETTLE_S = 0.25     # [s] from the start: the liquid still settles on its cell (-0.5 % in that span)
FILL_THETA_MAX = np.radians(20.0)  # [rad] below it nothing has left: an ideal liquid below 12.7 L in the default
                                   # bucket first leaves beyond it (41° at 10 L), the circle pile later still
FILL_TICKS_MIN = 1000    # [ticks] of readings the mean needs: ~80 conversions


def fit_fill(run: Run, rig: dict) -> Estimate:
    """fill_depth [m] from the tilt experiment's log (the bucket filled as for a pour, the scales tared with
    it empty): the rotating cell's mean reading while the bucket tilts slowly through its first 20°, before
    any liquid leaves, is the liquid's mass; depth = mass / (liquid_density π (width/2)²), the
    simulator's own relation. At 0.1 rad/s the inertial load is ~1e-4 of the weight. The readings scatter
    by a few % as the liquid jostles on the cell (the cell's own noise, under a gram, is far below that):
    the standard deviation is the spread of 8 contiguous batch means over √8, the liquid's density being
    the base rig's (the recipe's) and taken as exact."""
    if run.kind != 2:
        raise LogError("the fill's log is of the identify experiment (bucket empty): weighing the fill needs the "
                       "tilt experiment's (pour-bench identify --kind tilt, the bucket filled)")
    theta = run.theta(int(rig["encoder_bits"]))
    t = run.t - run.t[0]
    use = (run.action == FILL_PHASE) & (theta < FILL_THETA_MAX) & (t >= FILL_SETTLE_S)
    if use.sum() < FILL_TICKS_MIN:
        raise LogError(f"cannot weigh the fill: {int(use.sum())} ticks of the tilt below "
                       f"{np.degrees(FILL_THETA_MAX):.0f}° after the first {FILL_SETTLE_S} s (at least "
                       f"{FILL_TICKS_MIN}): a faster tilt than 0.1 rad/s?")
    reading = run.scale_rotating[use]
    mass_g = float(np.mean(reading))
    batches = np.array([b.mean() for b in np.array_split(reading, BATCHES)])
    sigma_g = float(np.std(batches, ddof=1) / np.sqrt(BATCHES))
    area = np.pi * (0.5 * rig["bucket_inner_width"]) ** 2
    per_m = rig["liquid_density"] * area * 1000.0   # [g] per metre of depth
    depth, sigma = mass_g / per_m, sigma_g / per_m
    inner = rig["bucket_height"] - rig["bucket_wall"]
    if mass_g < 20 * rig["scale_resolution_g"] or depth > inner:
        raise LogError(f"the rotating scale weighs {mass_g:.0f} g before the tilt, a depth of {depth * 100:.1f} cm "
                       f"at liquid_density {rig['liquid_density']:g} kg/m^3 (the bucket is {inner * 100:.1f} cm "
                       "deep): no water in the bucket, or the scales were not tared with it empty")
    litres = area * depth * 1000.0
    return Estimate(depth, sigma, "m", f"the liquid's depth upright: {mass_g:.0f} +- {sigma_g:.0f} g weighed "
                                       f"before the tilt, {litres:.2f} L at liquid_density {rig['liquid_density']:g}")
