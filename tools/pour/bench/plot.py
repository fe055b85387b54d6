# SPDX-License-Identifier: MIT
"""The live plot of one node (pour-bench plot): tilt θ and its rate θ̇, the torque command, both scales, the
drive's q current and bus voltage, and the mode and fault timeline, from the frames on the bus (or a candump
log, replayed at its own pace).

Time is the samples' own clock: the Sensors frames' Seq, counted on across its 8-bit wraps, at 1 ms a sample
(a real-time bench runs it at the wall clock's pace; a lockstep run with a simulated plant at the plant's), and
every other frame is placed at the latest sample's time. θ comes from the Sensors frames' encoder count (rad = count · 2π / 2^bits, below upright wraps); θ̇ is its
rate over a short window (the controller's own estimate does not cross the bus); the torque is the Torque
frames' fraction of τ_max times Identity.TauMax. The drive's q current, bus voltage and latched faults come
from its DriveTelemetry frames (one a heartbeat, scaled by the DBC); a node without a drive of its own sends
none, and the figure says so.
"""
from __future__ import annotations

import math
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

import can

from pour import atomic
from pour.bench import node as bn

RATE_WINDOW_S = 0.02  # θ̇ over 20 ms of samples: the encoder's quantisation noise averaged out


@dataclass
class Series:
    """The node's signals against the samples' time [s], trimmed to the last window_s seconds."""
    window_s: float
    encoder_bits: int
    seq: int | None = None  # samples so far, the 8-bit Seq counted on
    theta: deque = field(default_factory=deque)     # (t, deg)
    omega: deque = field(default_factory=deque)     # (t, deg/s)
    torque: deque = field(default_factory=deque)    # (t, N·m)
    scales: deque = field(default_factory=deque)    # (t, rotating kg, target kg)
    modes: deque = field(default_factory=deque)     # (t, mode index)
    faults: deque = field(default_factory=deque)    # (t, [fault names])
    drive: deque = field(default_factory=deque)     # (t, Iq A, bus V, [drive fault names]), DriveTelemetry
    tau_max_nm: float | None = None
    last_count: deque = field(default_factory=lambda: deque(maxlen=64))  # (t, θ rad) for the rate

    def add(self, name: str, sig: dict, fault_names: list[str]) -> None:
        if name == "Sensors":
            self.seq = sig["Seq"] if self.seq is None else self.seq + ((sig["Seq"] - self.seq) % 256)
        t = (self.seq or 0) * 0.001
        if name == "Sensors":
            n = 1 << self.encoder_bits
            c = sig["Encoder"] % n
            th = 2 * math.pi * (c - n if c >= n // 2 else c) / n
            self.theta.append((t, math.degrees(th)))
            self.last_count.append((t, th))
            while len(self.last_count) > 2 and t - self.last_count[0][0] > RATE_WINDOW_S:
                self.last_count.popleft()
            (ta, a), (tb, b) = self.last_count[0], self.last_count[-1]
            if tb > ta:
                self.omega.append((t, math.degrees((b - a) / (tb - ta))))
            self.scales.append((t, sig["ScaleRotating"] / 1000.0, sig["ScaleTarget"] / 1000.0))
        elif name == "Torque" and self.tau_max_nm is not None:
            self.torque.append((t, sig["Torque"] / 32768.0 * self.tau_max_nm))
        elif name == "Identity":
            self.tau_max_nm = sig["TauMax"] * 0.01
        elif name == "Heartbeat":
            self.modes.append((t, sig["Mode"]))
            self.faults.append((t, [f.removeprefix("Fault_") for f in fault_names if sig[f]]))
        self._trim(t)

    def add_drive(self, tel: bn.DriveTelemetry) -> None:
        """A DriveTelemetry frame (node.drive_telemetry: SI units), at the latest sample's time."""
        t = (self.seq or 0) * 0.001
        self.drive.append((t, tel.iq_a, tel.vbus_v, list(tel.faults)))
        self._trim(t)

    def _trim(self, t: float) -> None:
        for q in (self.theta, self.omega, self.torque, self.scales, self.modes, self.faults, self.drive):
            while q and t - q[0][0] > self.window_s:
                q.popleft()


class Figure:
    """The matplotlib figure: seven panels sharing the time axis."""

    def __init__(self, node_id: int, fault_names: list[str], mode_names: dict[int, str], interactive: bool) -> None:
        import matplotlib
        if not interactive:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        self.plt = plt
        if interactive:
            plt.ion()
        self.fig, ax = plt.subplots(7, 1, sharex=True, figsize=(10, 12), height_ratios=[2, 2, 2, 2, 2, 2, 1.6])
        self.ax = ax
        self.fault_names = [f.removeprefix("Fault_") for f in fault_names]
        self.fig.suptitle(f"pour-bench plot: node {node_id}", fontsize=10)
        (self.l_theta,) = ax[0].plot([], [], lw=1)
        ax[0].set_ylabel("θ [deg]")
        (self.l_omega,) = ax[1].plot([], [], lw=1, color="tab:orange")
        ax[1].set_ylabel("θ̇ [deg/s]")
        (self.l_torque,) = ax[2].plot([], [], lw=1, color="tab:red")
        ax[2].set_ylabel("torque cmd [N·m]")
        (self.l_rot,) = ax[3].plot([], [], lw=1, label="rotating")
        (self.l_tgt,) = ax[3].plot([], [], lw=1, label="target")
        ax[3].set_ylabel("scales [kg]")
        ax[3].legend(loc="upper left", fontsize=8)
        (self.l_iq,) = ax[4].plot([], [], lw=1, color="tab:purple")
        ax[4].set_ylabel("drive Iq [A]")
        (self.l_vbus,) = ax[5].plot([], [], lw=1, color="tab:green")
        ax[5].set_ylabel("bus [V]")
        self.drive_text = ax[4].text(0.01, 0.92, "", transform=ax[4].transAxes, va="top", fontsize=8)
        (self.l_mode,) = ax[6].step([], [], where="post", color="k", lw=1.2)
        ax[6].set_yticks(sorted(mode_names), [mode_names[k] for k in sorted(mode_names)], fontsize=8)
        ax[6].set_ylim(-0.5, max(mode_names) + 0.5)
        ax[6].set_ylabel("mode")
        ax[6].set_xlabel("time [s] (samples at 1 ms)")
        self.fault_text = ax[6].text(0.01, 0.92, "", transform=ax[6].transAxes, va="top", fontsize=8, color="tab:red")
        for a in ax:
            a.grid(True, alpha=0.3)
        self.fig.tight_layout()

    def update(self, s: Series) -> None:
        def xy(q, i=1):
            return [p[0] for p in q], [p[i] for p in q]

        self.l_theta.set_data(*xy(s.theta))
        self.l_omega.set_data(*xy(s.omega))
        self.l_torque.set_data(*xy(s.torque))
        self.l_rot.set_data(*xy(s.scales, 1))
        self.l_tgt.set_data(*xy(s.scales, 2))
        self.l_iq.set_data(*xy(s.drive, 1))
        self.l_vbus.set_data(*xy(s.drive, 2))
        self.drive_text.set_text("" if s.drive else "no DriveTelemetry from this node (no drive of its own)")
        self.l_mode.set_data(*xy(s.modes))
        # Faults as a timeline: each latched fault's first and last heartbeat (the drive's: telemetry frame) in
        # the window.
        spans: dict[str, list[float]] = {}
        for t, names in s.faults:
            for n in names:
                spans.setdefault(n, [t, t])[1] = t
        for t, _, _, names in s.drive:
            for n in names:
                spans.setdefault("drive " + n, [t, t])[1] = t
        self.fault_text.set_text("faults: " + ", ".join(f"{n} {a:.1f}-{b:.1f} s" for n, (a, b) in spans.items())
                                 if spans else "faults: none")
        for a in self.ax[:6]:
            a.relim()
            a.autoscale_view()
        ts = [q[-1][0] for q in (s.theta, s.modes) if q]
        if ts:
            hi = max(ts)
            self.ax[6].set_xlim(max(0.0, hi - s.window_s), max(hi, 1e-3))
        self.fig.canvas.draw_idle()

    def pause(self, seconds: float) -> None:
        self.plt.pause(seconds)

    def save(self, path: Path) -> None:
        with atomic.atomic_path(path) as tmp:
            self.fig.savefig(tmp, dpi=100, format="png")


def replay(path: Path, paced: bool = True) -> Iterable[can.Message]:
    """The frames of a candump -L log, at their recorded pace (paced) or as fast as they are drawn."""
    try:
        reader = can.CanutilsLogReader(str(path))
        msgs = list(reader)
    except (OSError, ValueError) as e:
        raise bn.BenchError(f"{path}: not a candump -L log ({e})") from e
    if not msgs:
        raise bn.BenchError(f"{path}: no frames")
    start, t0 = time.monotonic(), msgs[0].timestamp
    for m in msgs:
        wait = (m.timestamp - t0) - (time.monotonic() - start)
        if paced and wait > 0:
            time.sleep(wait)
        yield m


def run(frames: Iterable[can.Message], bench_db, node_id: int, seconds: float, encoder_bits: int, window_s: float,
        png: Path | None, interactive: bool, hold: bool = False) -> int:
    """Feeds frames of node_id into the figure for seconds; saves png at the end; hold: the window stays until
    it is closed. Returns the frames used."""
    decoder = bn.Decoder(bench_db)
    fault_names = bn.fault_signals(bench_db)
    modes = bench_db.get_message_by_name("Heartbeat").get_signal_by_name("Mode").choices
    fig = Figure(node_id, fault_names, {int(k): str(v) for k, v in modes.items()}, interactive)
    s = Series(window_s, encoder_bits)
    used = 0
    end = time.monotonic() + seconds
    next_draw = 0.0
    for msg in frames:
        d = decoder.decode(msg)
        if d is not None and d[0] == node_id:
            if d[1] == "DriveTelemetry":
                s.add_drive(bn.drive_telemetry(bench_db, d[2]))
            else:
                s.add(d[1], d[2], fault_names)
            used += 1
        now = time.monotonic()
        if now >= next_draw:
            fig.update(s)
            if interactive:
                fig.pause(0.001)
            next_draw = now + 0.2
        if now >= end:
            break
    if used == 0:
        raise bn.BenchError(f"no frame of node {node_id} to plot")
    fig.update(s)
    if png is not None:
        fig.save(png)
    if interactive and hold:
        print(f"pour-bench plot: {used} frames of node {node_id}; close the window to end", flush=True)
        fig.plt.show(block=True)
    return used
