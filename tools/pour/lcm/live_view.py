# SPDX-License-Identifier: MIT
"""pour-live-view: watch a running pour from POUR_PARTICLES (host_sim --lcm publishes ~30 frames/s).

    pour-live-view [--url URL]                          # a window, for a person at the bench
    pour-live-view --save view.png --frames 30          # headless: the 30th frame as a PNG, then exit

The picture is host_sim's render (tools/pour/eval/render.py): buckets, liquid coloured by where it is,
θ and the shares in bucket, target and spilled; under it, the latest raw sensor sample the controller
was sent (POUR_SENSORS: encoder count, the two scales) and the controller's last status.
"""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import matplotlib

from pour import cli, functions
from pour.lcm import channels, messages, sensors


def scene_data(p) -> dict:
    """render.py's trajectory dict holding one frame, from a particles_t."""
    return {"scene": {"inner_width": p.bucket_inner_width, "height": p.bucket_height, "wall": p.bucket_wall,
                      "pivot_x": p.pivot_x, "pivot_y": p.pivot_y, "target_x": p.target_x, "theta_max": p.theta_max},
            "radius": list(p.r), "frames": [frame(p)]}


def frame(p) -> dict:
    xy = [c for pair in zip(p.x, p.y) for c in pair]
    return {"t": p.seq * 1e-3, "theta": p.theta, "xy": xy}


class LiveView:
    """Keeps the newest particles and status; draws on demand."""

    def __init__(self, url: str):
        import lcm

        self.m = messages.load()
        self.lc = lcm.LCM(url)
        self.latest = None
        self.status = None
        self.sample = None
        self.frames = 0
        self.dropped = 0
        self.lc.subscribe(channels.PARTICLES, self._on_particles)
        self.lc.subscribe(channels.STATUS, self._on_status)
        self.lc.subscribe(channels.SENSORS, self._on_sensors)

    def _on_particles(self, channel: str, data: bytes) -> None:
        try:
            p = self.m.particles_t.decode(data)
        except Exception:
            self.dropped += 1
            return
        if p.n <= 0 or not (p.bucket_inner_width > 0 and p.bucket_height > 0):
            self.dropped += 1
            return
        self.latest = p
        self.frames += 1

    def _on_status(self, channel: str, data: bytes) -> None:
        try:
            self.status = self.m.controller_status_t.decode(data)
        except Exception:
            self.dropped += 1

    def _on_sensors(self, channel: str, data: bytes) -> None:
        try:
            self.sample = self.m.sensor_sample_t.decode(data)
        except Exception:
            self.dropped += 1

    def sensors_text(self) -> str:
        s = self.sample
        if s is None:
            return f"sensors: no {channels.SENSORS} yet"
        try:
            angle = f"{math.degrees(sensors.encoder_angle(s.encoder)):6.1f}°"
        except ValueError:
            angle = "out of range"  # the controller latches BAD_INPUT on such a count
        return (f"sensors: encoder {s.encoder:6d} ({angle})  scales {s.scale_rotating_g:6d} g"
                f" / {s.scale_target_g:6d} g")

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            self.lc.handle_timeout(max(1, int(left * 1000)))

    def status_text(self) -> str:
        s = self.status
        if s is None:
            return "controller: no POUR_STATUS yet"
        faults = s.faults & 0xFFFF
        named = f" ({', '.join(functions.fault_names(faults))})" if faults else ""
        return (f"controller {functions.mode_name(s.mode) or s.mode}  faults 0x{faults:04x}{named}"
                f"  overruns {s.overruns}  dropped {s.messages_dropped}")


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-live-view", description=__doc__.split("\n\n")[0])
    ap.add_argument("--lcm", "--url", dest="url", metavar="URL", default=channels.DEFAULT_URL, help="LCM URL (default %(default)s)")
    ap.add_argument("--save", type=Path, help="headless: save the --frames-th frame as a PNG and exit")
    ap.add_argument("--frames", type=int, default=30, help="with --save: frames to wait for (default 30)")
    ap.add_argument("--timeout", type=float, default=10.0, help="give up after this long without a frame [s]")
    ap.add_argument("--seconds", type=float, help="window: close it after this long [s] (default: when closed)")
    a = ap.parse_args(argv)
    if a.frames < 1 or not a.timeout > 0 or (a.seconds is not None and not a.seconds > 0):
        ap.error("--frames must be >= 1, --timeout and --seconds positive")
    if a.save is None and not os.environ.get("DISPLAY"):
        print("pour-live-view: error: no DISPLAY; use --save FILE.png for a headless snapshot", file=sys.stderr)
        return 2
    if a.save is not None:
        matplotlib.use("Agg")
    backend = matplotlib.get_backend()  # resolved now: render.py selects Agg when it is imported
    import matplotlib.pyplot as plt

    from pour.eval import render

    if a.save is None:
        if backend.lower() in ("agg", "pdf", "svg", "ps", "cairo"):
            print(f"pour-live-view: error: matplotlib has no window backend here ({backend}); "
                  "install python3-tk (scripts/setup.sh does), or use --save FILE.png", file=sys.stderr)
            return 2
        plt.switch_backend(backend)

    view = LiveView(a.url)
    deadline = time.monotonic() + a.timeout
    while view.latest is None:
        if time.monotonic() > deadline:
            print(f"pour-live-view: error: no {channels.PARTICLES} on {a.url} within {a.timeout:g} s "
                  "(is host_sim --lcm running?)", file=sys.stderr)
            return 1
        view.pump(0.05)
    fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=90)
    scene = render.Scene(ax, scene_data(view.latest))
    footer = fig.text(0.02, 0.01, "", family="monospace", fontsize=8)
    shown = -1

    def draw() -> None:
        nonlocal shown
        if view.frames == shown:
            return
        shown = view.frames
        scene.data["frames"] = [frame(view.latest)]
        scene.update(0)
        footer.set_text(view.sensors_text() + "\n" + view.status_text())

    if a.save is not None:
        last = time.monotonic()
        while view.frames < a.frames:
            n = view.frames
            view.pump(0.05)
            if view.frames != n:
                last = time.monotonic()
            elif time.monotonic() - last > a.timeout:
                print(f"pour-live-view: error: {channels.PARTICLES} stopped after {view.frames} frames",
                      file=sys.stderr)
                return 1
        draw()
        fig.savefig(a.save)
        print(f"pour-live-view: {a.save} (frame {view.frames}, t = {view.latest.seq * 1e-3:.2f} s)")
        return 0
    plt.ion()
    plt.show()
    end = None if a.seconds is None else time.monotonic() + a.seconds
    while plt.fignum_exists(fig.number) and (end is None or time.monotonic() < end):
        view.pump(0.02)
        draw()
        plt.pause(0.001)
    print(f"pour-live-view: {view.frames} frames shown, {view.dropped} undecodable dropped")
    return 0


if __name__ == "__main__":
    sys.exit(main())
