# SPDX-License-Identifier: MIT
"""pour-live-view (headless) and pour-lcm-cmd against live traffic; their bad inputs."""
import os
import random
import subprocess
import sys
import threading
import time

import numpy as np
from PIL import Image

from lcm_helpers import Bus, Proc, binary, compiled_weights, msgs, url
from pour.lcm import channels


def test_live_view_draws_a_running_pour_and_ignores_garbage(build_dir, source_dir, tmp_path):
    u = url(41)
    png = tmp_path / "live.png"
    bus = Bus(u)
    stop = threading.Event()

    def spam() -> None:
        rng = random.Random(4)
        while not stop.is_set():
            bus.lc.publish(channels.PARTICLES, bytes(rng.randrange(256) for _ in range(64)))
            stop.wait(0.01)

    t = threading.Thread(target=spam)
    with Proc([binary(build_dir, "pour_controller"), "--io", f"lcm:{u}", "--lockstep"]), \
         Proc([binary(build_dir, "host_sim"), "--policy", compiled_weights(build_dir), "--lcm", u,
               "--realtime", "--set", "episode_s=10"]):
        t.start()
        try:
            r = subprocess.run([sys.executable, "-m", "pour.lcm.live_view", "--url", u, "--save", png, "--frames", "5"],
                               capture_output=True, text=True, timeout=120)
        finally:
            stop.set()
            t.join()
    assert r.returncode == 0, r.stderr
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    # Liquid is drawn in cream (0.96, 0.88, 0.70) or blue/red: plenty of such pixels.
    cream = (abs(img[:, :, 0] - 245) < 12) & (abs(img[:, :, 1] - 224) < 12) & (abs(img[:, :, 2] - 178) < 12)
    assert cream.sum() > 500


def test_live_view_without_traffic_fails_clearly():
    r = subprocess.run([sys.executable, "-m", "pour.lcm.live_view", "--url", url(42), "--save", "x.png", "--timeout",
                        "0.5"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "no POUR_PARTICLES" in r.stderr


def test_live_view_rejects_bad_arguments():
    r = subprocess.run([sys.executable, "-m", "pour.lcm.live_view", "--save", "x.png", "--frames", "0"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--frames must be >= 1" in r.stderr


def test_lcm_cmd_estop_and_clear_reach_the_controller(build_dir):
    u = url(43)
    bus = Bus(u)
    with Proc([binary(build_dir, "pour_controller"), "--io", f"lcm:{u}", "--lockstep"]) as c:
        bus.ask(0, theta=0.3)

        def cmd(*flags: str) -> None:
            r = subprocess.run([sys.executable, "-m", "pour.lcm.cmd", "--url", u, *flags], capture_output=True,
                               text=True, timeout=60)
            assert r.returncode == 0, r.stderr
            bus.pump(0.05)

        cmd("--estop")
        assert bus.ask(1, theta=0.3).mode == 3
        cmd("--release")
        assert bus.ask(2, theta=0.3).mode == 2
        cmd("--clear")
        bus.ask(3, theta=0.3)
        assert bus.ask(4, theta=0.3).mode == 1
        cmd("--new-run")  # stop + reset: the next state, seq 0, starts a fresh run
        assert bus.ask(0, episode=1, theta=0.3).mode == 1
        assert c.stop() == 0
    assert "resets 1" in c.out


def test_lcm_cmd_bad_inputs():
    r = subprocess.run([sys.executable, "-m", "pour.lcm.cmd", "--url", "nosuchprovider://x", "--clear"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "cannot open LCM" in r.stderr
    r = subprocess.run([sys.executable, "-m", "pour.lcm.cmd", "--clear", "--estop"], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 2 and "not allowed with" in r.stderr


def test_lcm_run_pours_through_two_processes(build_dir, source_dir):
    r = subprocess.run([sys.executable, "-m", "pour.lcm.run", "--build-dir", build_dir, "--",
                        "--policy", compiled_weights(build_dir), "--set", "episode_s=0.5"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "lcm lockstep: samples 500 answers 500 on_time 500" in r.stdout
    assert "pour_controller: ticks" in r.stdout and "answers 500" in r.stdout


def test_lcm_run_passes_on_host_sim_failures_and_refuses_doubled_flags(build_dir):
    r = subprocess.run([sys.executable, "-m", "pour.lcm.run", "--build-dir", build_dir, "--", "--policy",
                        "/nonexistent/weights.h"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "bad policy" in r.stderr
    r = subprocess.run([sys.executable, "-m", "pour.lcm.run", "--", "--lcm", "x"], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 2 and "not to host_sim" in r.stderr


def test_live_view_window_under_xvfb(build_dir, source_dir, tmp_path):
    from pour.lcm import spy

    u = url(44)
    xvfb, display = spy.start_xvfb("800x600x24")
    try:
        env = dict(os.environ, DISPLAY=display, MPLBACKEND="TkAgg")
        with Proc([binary(build_dir, "pour_controller"), "--io", f"lcm:{u}", "--lockstep"]), \
             Proc([binary(build_dir, "host_sim"), "--policy", compiled_weights(build_dir), "--lcm", u,
                   "--realtime", "--set", "episode_s=8"]):
            p = subprocess.Popen([sys.executable, "-m", "pour.lcm.live_view", "--url", u, "--seconds", "6"], env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            white = 0
            for _ in range(40):  # the window appears once Python, matplotlib and Tk have started
                time.sleep(0.25)
                rgb = spy.screenshot(display, tmp_path / "window.png")
                white = int((rgb.sum(axis=2) > 600).sum())
                if white > 50000 or p.poll() is not None:
                    break
            out, err = p.communicate(timeout=60)
    finally:
        spy.stop(xvfb)
    assert p.returncode == 0, err
    frames = int(out.split("pour-live-view: ")[1].split()[0])
    assert frames > 10
    assert white > 50000  # a white figure covers much of the black root window


def test_live_view_shows_the_raw_sample_and_flags_an_impossible_count():
    from pour.lcm import live_view

    view = live_view.LiveView(url(45))
    assert "no POUR_SENSORS yet" in view.sensors_text()
    s = msgs.sensor_sample_t()
    s.encoder, s.scale_rotating_g, s.scale_target_g = 32768, 7725, 2575  # a quarter turn: 90°
    view._on_sensors(channels.SENSORS, s.encode())
    assert view.sensors_text() == "sensors: encoder  32768 (  90.0°)  scales   7725 g /   2575 g"
    s.encoder = 1 << 17  # no count of the 17-bit encoder: the controller latches BAD_INPUT on it
    view._on_sensors(channels.SENSORS, s.encode())
    assert "(out of range)" in view.sensors_text()
    view._on_sensors(channels.SENSORS, b"garbage")
    assert view.dropped == 1
