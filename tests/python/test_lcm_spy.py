# SPDX-License-Identifier: MIT
"""lcm-spy with our jar under Xvfb: it finds every pour type and draws its window; the XWD reader."""
import struct
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from lcm_helpers import Proc, binary, url
from pour import paths
from pour.lcm import spy


def make_xwd(rgb: np.ndarray, byte_order: int = 0) -> bytes:
    h, w, _ = rgb.shape
    name = b"test\0"
    header = [100 + len(name), 7, 2, 24, w, h, 0, byte_order, 32, byte_order, 32, 32, 4 * w, 4,
              0xFF0000, 0x00FF00, 0x0000FF, 8, 256, 0, w, h, 0, 0, 0]
    px = (rgb[:, :, 0].astype(np.uint32) << 16) | (rgb[:, :, 1].astype(np.uint32) << 8) | rgb[:, :, 2]
    body = px.astype("<u4" if byte_order == 0 else ">u4").tobytes()
    return struct.pack(">25I", *header) + name + body


@pytest.mark.parametrize("byte_order", [0, 1])
def test_xwd_reader_decodes_truecolor(byte_order):
    rgb = np.random.default_rng(1).integers(0, 256, size=(7, 5, 3), dtype=np.uint8)
    assert np.array_equal(spy.xwd_to_rgb(make_xwd(rgb, byte_order)), rgb)


@pytest.mark.parametrize("mutate, needle", [
    (lambda d: d[:50], "shorter than its header"),
    (lambda d: d[:-10], "truncated XWD"),
    (lambda d: struct.pack(">I", 100 + 5) + struct.pack(">I", 6) + d[8:], "unsupported XWD"),
])
def test_xwd_reader_rejects_bad_files(mutate, needle):
    data = make_xwd(np.zeros((4, 4, 3), dtype=np.uint8))
    with pytest.raises(ValueError, match=needle):
        spy.xwd_to_rgb(mutate(data))


def test_lcm_spy_decodes_our_types_under_xvfb(build_dir, source_dir, tmp_path):
    controller = binary(build_dir, "pour_controller")
    driver = binary(build_dir, "lcm_loop_driver")
    u = url(21)
    png, log = tmp_path / "spy.png", tmp_path / "spy.log"
    with Proc([controller, "--io", f"lcm:{u}", "--lockstep"]), \
         Proc([driver, "--mode", "lcm", "--url", u, "--realtime", "--steps", "45000", "--particles-ms", "33"]):
        r = subprocess.run([sys.executable, "-m", "pour.lcm.spy", "--url", u, "--build-dir", build_dir,
                            "--screenshot", png, "--seconds", "6", "--log", log],
                           capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    n_types = len(list((source_dir / "lcmtypes" / "pour").glob("*.lcm")))
    assert f"Found {n_types} LCM types" in log.read_text()
    img = np.asarray(Image.open(png))
    assert img.shape == (800, 1280, 3)
    # The spy window (light grey, with dark text in its channel table) covers part of the black root.
    window = img[:560, :790].astype(int)
    assert window.mean() > 150
    dark = window.sum(axis=2) < 200
    assert dark[:19].sum() > 300  # the table header
    # One 16-pixel row of text per channel seen: state, torque, status, particles (+ LCM's self test).
    rows = [int(dark[19 + 16 * k: 35 + 16 * k].sum()) for k in range(10)]
    assert sum(r > 300 for r in rows) >= 4, rows


def test_lcm_spy_without_jar_says_what_to_build(tmp_path, monkeypatch):
    monkeypatch.delenv("POUR_BUILD_DIR", raising=False)
    monkeypatch.setattr(paths, "SOURCE_DIR", tmp_path)
    with pytest.raises(SystemExit, match="pour_lcmtypes.jar not found"):
        spy.find_jar(str(tmp_path))


def test_lcm_spy_rejects_bad_seconds():
    r = subprocess.run([sys.executable, "-m", "pour.lcm.spy", "--screenshot", "x.png", "--seconds", "0"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--seconds must be positive" in r.stderr
