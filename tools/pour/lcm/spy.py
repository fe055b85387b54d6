# SPDX-License-Identifier: MIT
"""pour-lcm-spy: lcm-spy with pour's message types on its classpath, so it decodes them live.

    pour-lcm-spy [--url URL]                      # a window on the current DISPLAY
    pour-lcm-spy --screenshot spy.png --seconds 5 # headless: own Xvfb, a PNG of the screen, then exit

The jar of the generated Java classes is built by CMake (lcmtypes/pour_lcmtypes.jar in the build tree).
"""
from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import sysconfig
import time
from pathlib import Path

import numpy as np

from pour import cli, paths
from pour.lcm import channels

def find_jar(build_dir: str | None = None) -> Path:
    """The types jar: --build-dir, then $POUR_BUILD_DIR, then build/host of the source tree."""
    jar = paths.find(Path("lcmtypes") / "pour_lcmtypes.jar", build_dir)
    if jar is not None:
        return jar
    dirs = paths.build_dirs(build_dir)
    raise SystemExit("error: pour_lcmtypes.jar not found in " + ", ".join(str(d / "lcmtypes") for d in dirs)
                     + "; build first (cmake --workflow --preset host)")


def spy_script() -> Path:
    """lcm-spy's own launcher script from the LCM wheel (not the venv's Python wrapper)."""
    path = Path(sysconfig.get_paths()["purelib"]) / "bin" / "lcm-spy"
    if not path.is_file():
        raise SystemExit(f"error: {path} not found: is the lcm wheel installed in this venv?")
    return path


def spy_env(jar: Path) -> dict:
    env = dict(os.environ)
    env["CLASSPATH"] = str(jar) + (os.pathsep + env["CLASSPATH"] if env.get("CLASSPATH") else "")
    return env


def xwd_to_rgb(data: bytes) -> np.ndarray:
    """Decodes an X window dump (TrueColor, 24/32 bits per pixel, as xwd writes for Xvfb) to HxWx3 uint8."""
    if len(data) < 100:
        raise ValueError("not an XWD file: shorter than its header")
    h = np.frombuffer(data[:100], dtype=">u4")
    header_size, version, fmt = int(h[0]), int(h[1]), int(h[2])
    width, height, byte_order = int(h[4]), int(h[5]), int(h[7])
    bpp, bytes_per_line, visual = int(h[11]), int(h[12]), int(h[13])
    masks = [int(h[14]), int(h[15]), int(h[16])]
    ncolors = int(h[19])
    if version != 7 or fmt != 2:
        raise ValueError(f"unsupported XWD (version {version}, format {fmt}): need version 7 ZPixmap")
    if visual not in (4, 5) or bpp not in (24, 32):
        raise ValueError(f"unsupported XWD visual {visual} / {bpp} bits per pixel: need TrueColor 24/32")
    start = header_size + 12 * ncolors
    need = start + bytes_per_line * height
    if len(data) < need:
        raise ValueError(f"truncated XWD: {len(data)} bytes, need {need}")
    rows = np.frombuffer(data[start:need], dtype=np.uint8).reshape(height, bytes_per_line)
    step = bpp // 8
    px = rows[:, : width * step].reshape(height, width, step).astype(np.uint32)
    order = range(step) if byte_order == 0 else range(step - 1, -1, -1)  # 0: LSB first
    value = np.zeros((height, width), dtype=np.uint32)
    for shift, i in enumerate(order):
        value |= px[:, :, i] << np.uint32(8 * shift)
    out = np.zeros((height, width, 3), dtype=np.uint8)
    for c, m in enumerate(masks):
        low = (m & -m).bit_length() - 1
        out[:, :, c] = ((value & np.uint32(m)) >> np.uint32(low)).astype(np.uint8)
    return out


def start_xvfb(size: str = "1280x800x24") -> tuple[subprocess.Popen, str]:
    """An Xvfb on a free display number (it tells us which, through -displayfd)."""
    if shutil.which("Xvfb") is None:
        raise SystemExit("error: Xvfb not found (apt package xvfb; scripts/setup.sh installs it)")
    r, w = os.pipe()
    p = subprocess.Popen(["Xvfb", "-displayfd", str(w), "-screen", "0", size, "-nolisten", "tcp"],
                         pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    with os.fdopen(r) as f:
        display = f.readline().strip()
    if not display:
        p.kill()
        raise SystemExit("error: Xvfb did not start")
    return p, ":" + display


def screenshot(display: str, png: Path) -> np.ndarray:
    """Dumps the root window of display with xwd and writes it as a PNG (Pillow)."""
    from PIL import Image

    r = subprocess.run(["xwd", "-root", "-silent", "-display", display], capture_output=True, timeout=30)
    if r.returncode != 0:
        raise SystemExit(f"error: xwd failed: {r.stderr.decode(errors='replace').strip()}")
    rgb = xwd_to_rgb(r.stdout)
    Image.fromarray(rgb).save(png)
    return rgb


def stop(p: subprocess.Popen) -> None:
    if p.poll() is None:
        p.send_signal(signal.SIGTERM)
        try:
            p.wait(timeout=5)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-lcm-spy", description=__doc__.split("\n\n")[0])
    ap.add_argument("--lcm", "--url", dest="url", metavar="URL", default=channels.DEFAULT_URL, help="LCM URL (default %(default)s)")
    ap.add_argument("--build-dir", help="CMake build tree holding lcmtypes/pour_lcmtypes.jar")
    ap.add_argument("--screenshot", type=Path, help="run under a private Xvfb and save a PNG of the screen")
    ap.add_argument("--seconds", type=float, default=5.0, help="with --screenshot: wait this long first")
    ap.add_argument("--log", type=Path, help="with --screenshot: write lcm-spy's output here")
    a = ap.parse_args(argv)
    if not a.seconds > 0:
        ap.error("--seconds must be positive")
    jar = find_jar(a.build_dir)
    cmd = [str(spy_script()), f"--lcm-url={a.url}", "--title", "pour"]
    env = spy_env(jar)
    if a.screenshot is None:
        if not env.get("DISPLAY"):
            print("error: no DISPLAY; use --screenshot for a headless check", file=sys.stderr)
            return 2
        os.execvpe(cmd[0], cmd, env)
    xvfb, display = start_xvfb()
    env["DISPLAY"] = display
    log = open(a.log, "w") if a.log else subprocess.DEVNULL
    spy = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT)
    try:
        time.sleep(a.seconds)
        if spy.poll() is not None:
            print(f"error: lcm-spy exited early with status {spy.returncode}", file=sys.stderr)
            return 1
        rgb = screenshot(display, a.screenshot)
        # A loaded machine may take longer to bring the JVM's window up: wait (bounded) for it.
        give_up, waited = time.monotonic() + 30.0, False
        while rgb.mean() < 10.0 and time.monotonic() < give_up and spy.poll() is None:
            waited = True
            time.sleep(0.5)
            rgb = screenshot(display, a.screenshot)
        if waited and rgb.mean() >= 10.0:
            time.sleep(2.0)  # a moment of traffic in the window that came late
            rgb = screenshot(display, a.screenshot)
    finally:
        stop(spy)
        stop(xvfb)
        if a.log:
            log.close()
    print(f"pour-lcm-spy: {a.screenshot} ({rgb.shape[1]}x{rgb.shape[0]}), types from {jar}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
