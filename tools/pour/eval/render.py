# SPDX-License-Identifier: MIT
"""Render a host_sim pour: an animation (GIF or MP4) and a PNG snapshot.

host_sim --render FILE writes FILE's trajectory as JSON (scene, circle radii, circle positions at
12.5 frames/s, θ and volumes at 100 Hz) and calls this script:

    python -m pour.eval.render TRAJECTORY.json OUT.gif|OUT.mp4

The picture: the rotating bucket (grey, on its pivot), the target bucket, the liquid (cream in a
bucket, blue in the air, red once spilled), and beside it θ and the three volumes over time.
"""
from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import animation  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402

from pour import atomic, cli  # noqa: E402

COLOURS = np.array([[0.96, 0.88, 0.70, 1.0],   # in the rotating bucket
                    [0.96, 0.88, 0.70, 1.0],   # in the target
                    [0.85, 0.15, 0.10, 1.0],   # spilled
                    [0.35, 0.60, 0.90, 1.0]])  # in flight


class RenderError(RuntimeError):
    pass


def load(path: Path) -> dict:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        raise RenderError(f"cannot read trajectory {path}: {e}") from e
    for key in ("scene", "radius", "series", "frames"):
        if key not in data:
            raise RenderError(f"trajectory {path} has no '{key}'")
    if not data["frames"]:
        raise RenderError(f"trajectory {path} has no frames")
    return data


def bucket_boxes(scene: dict) -> list[np.ndarray]:
    """The three boxes (bottom, left, right) of a bucket, corners in its own frame [m]."""
    wi, w, hh = scene["inner_width"] / 2, scene["wall"], scene["height"] / 2
    boxes = [(-wi - w, -hh, wi + w, -hh + w), (-wi - w, -hh, -wi, hh), (wi, -hh, wi + w, hh)]
    return [np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]) for x0, y0, x1, y1 in boxes]


def rotate(points: np.ndarray, theta: float, pivot: np.ndarray) -> np.ndarray:
    """θ tilts clockwise (toward the target on the right)."""
    c, s = math.cos(theta), math.sin(theta)
    r = np.array([[c, s], [-s, c]])
    return points @ r.T + pivot


def regions(xy: np.ndarray, theta: float, scene: dict) -> np.ndarray:
    """Same rules as libpoursim: rotating bucket (its frame), target, spilled (below the rim), flight."""
    wi, hh, wall = scene["inner_width"] / 2, scene["height"] / 2, scene["wall"]
    pivot = np.array([scene["pivot_x"], scene["pivot_y"]])
    c, s = math.cos(theta), math.sin(theta)
    local = (xy - pivot) @ np.array([[c, -s], [s, c]]).T  # inverse of rotate()
    rot = (np.abs(local[:, 0]) <= wi) & (local[:, 1] >= -hh + wall) & (local[:, 1] <= hh)
    tx = scene["target_x"]
    rim = scene["height"]
    tgt = ~rot & (np.abs(xy[:, 0] - tx) <= wi) & (xy[:, 1] >= wall) & (xy[:, 1] <= rim)
    spill = ~rot & ~tgt & (xy[:, 1] < rim)
    out = np.full(len(xy), 3)
    out[rot], out[tgt], out[spill] = 0, 1, 2
    return out


class Scene:
    """Draws one frame of the world into ax and updates it."""

    def __init__(self, ax, data: dict):
        self.data = data
        sc = data["scene"]
        self.pivot = np.array([sc["pivot_x"], sc["pivot_y"]])
        self.boxes = bucket_boxes(sc)
        ax.set_aspect("equal")
        ax.set_xlim(-0.30, sc["target_x"] + 0.30)
        ax.set_ylim(-0.02, sc["pivot_y"] + 0.30)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.add_patch(Rectangle((-1, -0.05), 3, 0.05, color="0.55"))  # ground
        tc = np.array([sc["target_x"], sc["height"] / 2])
        for b in self.boxes:
            ax.add_patch(Polygon(b + tc, closed=True, color="0.35"))
        self.rot = [ax.add_patch(Polygon(b + self.pivot, closed=True, color="0.45")) for b in self.boxes]
        ax.plot(*self.pivot, marker="o", color="k", ms=4, zorder=5)
        r = np.asarray(data["radius"])
        xy0 = self.xy(0)
        self.liquid = EllipseCollection(2 * r, 2 * r, np.zeros_like(r), units="xy", offsets=xy0,
                                        offset_transform=ax.transData, edgecolors="0.4", linewidths=0.3)
        ax.add_collection(self.liquid)
        self.text = ax.text(0.02, 0.98, "", transform=ax.transAxes, va="top", family="monospace", fontsize=8)
        self.update(0)

    def xy(self, k: int) -> np.ndarray:
        return np.asarray(self.data["frames"][k]["xy"], dtype=float).reshape(-1, 2)

    def update(self, k: int):
        fr = self.data["frames"][k]
        theta = fr["theta"]
        xy = self.xy(k)
        for patch, b in zip(self.rot, self.boxes):
            patch.set_xy(rotate(b, theta, self.pivot))
        reg = regions(xy, theta, self.data["scene"])
        self.liquid.set_offsets(xy)
        self.liquid.set_facecolors(COLOURS[reg])
        n = len(reg)
        self.text.set_text(f"t = {fr['t']:5.2f} s   θ = {math.degrees(theta):5.1f}°\n"
                           f"bucket {100 * np.sum(reg == 0) / n:5.1f} %  target {100 * np.sum(reg == 1) / n:5.1f} %"
                           f"  spilled {100 * np.sum(reg == 2) / n:4.1f} %")
        return [*self.rot, self.liquid, self.text]


def plot_series(ax_theta, ax_vol, data: dict):
    s = data["series"]
    t = np.asarray(s["t"])
    ax_theta.plot(t, np.degrees(s["theta"]), color="k")
    ax_theta.axhline(math.degrees(data["scene"]["theta_max"]), color="0.6", ls="--", lw=0.8)
    ax_theta.set_ylabel("θ [deg]")
    ax_theta.grid(alpha=0.3)
    ax_vol.plot(t, s["v_rotating"], label="in bucket", color="0.4")
    ax_vol.plot(t, s["v_target"], label="in target", color="tab:green")
    ax_vol.plot(t, s["v_spill"], label="spilled", color="tab:red")
    ax_vol.set_ylim(-0.02, 1.02)
    ax_vol.set_xlabel("t [s]")
    ax_vol.set_ylabel("fraction of liquid")
    ax_vol.legend(loc="center right", fontsize=8)
    ax_vol.grid(alpha=0.3)
    return [ax.axvline(0, color="tab:blue", lw=0.8) for ax in (ax_theta, ax_vol)]


def figure(data: dict):
    fig = plt.figure(figsize=(9.6, 5.0), dpi=80)
    gs = fig.add_gridspec(2, 2, width_ratios=[1.15, 1], hspace=0.15, wspace=0.25)
    ax_scene = fig.add_subplot(gs[:, 0])
    ax_theta = fig.add_subplot(gs[0, 1])
    ax_vol = fig.add_subplot(gs[1, 1], sharex=ax_theta)
    plt.setp(ax_theta.get_xticklabels(), visible=False)
    title = data.get("title", "pour")
    fin = data.get("finish_s", -1)
    fig.suptitle(f"{title}: poured {100 * data.get('poured', 0):.1f} %, spilled {100 * data.get('spilled', 0):.1f} %"
                 + (f", finished in {fin:.2f} s" if fin is not None and fin >= 0 else ""), fontsize=11)
    scene = Scene(ax_scene, data)
    cursors = plot_series(ax_theta, ax_vol, data)
    fig.subplots_adjust(left=0.07, right=0.98, top=0.91, bottom=0.1)
    return fig, scene, cursors


def snapshot_frame(data: dict) -> int:
    """The frame where the most liquid is in the air (the pour in full flow), else the middle."""
    best, best_k = -1, len(data["frames"]) // 2
    for k, fr in enumerate(data["frames"]):
        xy = np.asarray(fr["xy"], dtype=float).reshape(-1, 2)
        n_air = int(np.sum(regions(xy, fr["theta"], data["scene"]) == 3))
        if n_air > best:
            best, best_k = n_air, k
    return best_k


def render(traj: Path, out: Path, fps: float | None = None) -> tuple[Path, Path]:
    data = load(traj)
    fps = fps or float(data.get("fps", 12.5))
    suffix = out.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise RenderError(f"output {out} must end in .gif or .mp4")
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise RenderError("MP4 needs ffmpeg on PATH (apt install ffmpeg); use a .gif instead")
    png = out.with_suffix(".png")
    fig, scene, cursors = figure(data)
    k = snapshot_frame(data)
    scene.update(k)
    for c in cursors:
        c.set_xdata([data["frames"][k]["t"]] * 2)
    with atomic.atomic_path(png) as tmp:
        fig.savefig(tmp, dpi=100)

    def step(i: int):
        for c in cursors:
            c.set_xdata([data["frames"][i]["t"]] * 2)
        return scene.update(i) + cursors

    anim = animation.FuncAnimation(fig, step, frames=len(data["frames"]), blit=False)
    writer = animation.PillowWriter(fps=fps) if suffix == ".gif" else animation.FFMpegWriter(fps=fps)
    try:
        with atomic.atomic_path(out) as tmp:
            anim.save(str(tmp), writer=writer)
    finally:
        plt.close(fig)
    return out, png


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-render", description="Render a host_sim trajectory (JSON) as GIF/MP4 + PNG.",
                                 epilog="exit status (the same meanings in every pour program): 0 written; 1 a write "
                                        "failed; 2 bad input (the trajectory, the output name)")
    ap.add_argument("trajectory", type=Path, help="JSON written by host_sim --render")
    ap.add_argument("out", type=Path, help="animation to write: .gif or .mp4 (a .png snapshot goes beside it)")
    ap.add_argument("--fps", type=float, default=None, help="frames per second (default: as recorded)")
    args = ap.parse_args(argv)
    try:
        out, png = render(args.trajectory, args.out, args.fps)
    except RenderError as e:
        print(f"pour-render: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"pour-render: {e}", file=sys.stderr)
        return 1
    print(f"pour-render: wrote {out} and {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
