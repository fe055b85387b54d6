# SPDX-License-Identifier: MIT
"""A pour recorded by lcm-logger replays into pour-lcmlog: the summary matches host_sim's own, the
plots and the render are written; bad logs give clear errors."""
import json
import random
import signal
import subprocess
import sys
import sysconfig
import time
from pathlib import Path

import lcm
import pytest

from conftest import BUILD_DIR, SOURCE_DIR
from lcm_helpers import Bus, Proc, binary, compiled_weights, msgs, url
from pour import channels, lcmlog

LOGGER = Path(sysconfig.get_paths()["purelib"]) / "bin" / "lcm-logger"  # the real binary: it stops on SIGINT


def wait_until_still(path: Path, quiet_s: float = 0.5, limit_s: float = 10.0) -> None:
    """Wait until lcm-logger has written everything it received: the file stops growing."""
    deadline, size, since = time.monotonic() + limit_s, -1, time.monotonic()
    while time.monotonic() < deadline:
        now = path.stat().st_size if path.exists() else 0
        if now != size:
            size, since = now, time.monotonic()
        elif time.monotonic() - since >= quiet_s:
            return
        time.sleep(0.05)


def summary_line(text: str) -> str:
    return [x for x in text.splitlines() if x.startswith("summary")][0]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """One lockstep pour (2 s) through pour_controller, recorded with lcm-logger."""
    build_dir, source_dir = BUILD_DIR, SOURCE_DIR
    tmp = tmp_path_factory.mktemp("log")
    log = tmp / "pour.lcmlog"
    u = url(31)
    logger = subprocess.Popen([LOGGER, "-q", "-f", f"--lcm-url={u}", log])
    try:
        with Proc([binary(build_dir, "pour_controller"), "--io", f"lcm:{u}", "--lockstep"]) as c:
            bus = Bus(u)
            bus.wait_up()
            r = subprocess.run([binary(build_dir, "host_sim"), "--policy", compiled_weights(build_dir),
                                "--set", "episode_s=2", "--seed", "3", "--lcm", u],
                               capture_output=True, text=True, timeout=120)
            assert r.returncode == 0, r.stderr
            wait_until_still(log)
            c.stop()
    finally:
        logger.send_signal(signal.SIGINT)
        logger.wait(timeout=10)
    return log, r.stdout, tmp


def test_log_summary_matches_the_simulated_pour(recorded):
    log, host_out, tmp = recorded
    out = tmp / "plots"
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", log, "--out", out, "--json"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    (ep,) = s["episodes"]
    # host_sim's summary: poured/spilled after the last step; the log's last state is one step earlier.
    words = summary_line(host_out).split()
    poured, spilled = float(words[4]) / 100, float(words[9]) / 100
    assert abs(ep["poured"] - poured) <= 1 / 150 + 1e-9 and abs(ep["spilled"] - spilled) <= 1 / 150 + 1e-9
    # UDP multicast to the logger may drop a few datagrams on a loaded machine, anywhere in the stream
    # (the end included), states and answers alike.
    assert ep["first_seq"] <= 100 and ep["last_seq"] >= 1900
    assert s["states"] >= 1900 and s["unanswered"] <= 100
    assert s["latency_us"]["n"] == s["states"] - s["unanswered"] and s["latency_us"]["median"] > 0
    assert s["particle_frames"] > 0 and s["undecodable"] == {}
    for png in ("traces.png", "latency.png"):
        assert (out / png).stat().st_size > 10000
    assert json.loads((out / "summary.json").read_text())["episodes"] == s["episodes"]


def test_log_text_output_reads_like_host_sim(recorded):
    log, host_out, _ = recorded
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", log], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert summary_line(r.stdout).startswith("summary (1 episode): poured ")
    assert "latency POUR_STATE -> POUR_TORQUE: median" in r.stdout
    assert "controller: mode" in r.stdout


def test_log_renders_like_host_sim(recorded):
    log, _, tmp = recorded
    gif = tmp / "replay.gif"
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", log, "--render", gif], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    assert gif.stat().st_size > 10000 and gif.with_suffix(".png").stat().st_size > 10000
    traj = json.loads(gif.with_suffix(".json").read_text())
    assert len(traj["frames"]) >= 20 and len(traj["radius"]) == len(traj["frames"][0]["xy"]) // 2


def test_log_with_garbage_counts_it_and_still_analyses(tmp_path):
    path = tmp_path / "mixed.lcmlog"
    w = lcm.EventLog(str(path), "w", overwrite=True)
    bus_state = Bus.state  # encode helper without a bus
    rng = random.Random(2)
    for k in range(20):
        w.write_event(k * 1000, channels.STATE, bus_state(None, k, theta=0.01 * k))
        t = msgs.torque_t()
        t.seq, t.torque = k, 1.0
        w.write_event(k * 1000 + 80, channels.TORQUE, t.encode())
        w.write_event(k * 1000 + 90, channels.TORQUE, bytes(rng.randrange(256) for _ in range(30)))
    w.write_event(30000, channels.STATE, msgs.command_t().encode())
    w.write_event(30001, "SOMEONE_ELSE", b"ignored")
    w.close()
    s = lcmlog.analyse(path, None)
    assert s["undecodable"] == {channels.TORQUE: 20, channels.STATE: 1}
    assert s["states"] == 20 and s["unanswered"] == 0
    assert s["latency_us"]["median"] == 80


def test_missing_log_is_a_clear_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", tmp_path / "nope.lcmlog"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "no such log file" in r.stderr


def test_garbage_file_is_a_clear_error(tmp_path):
    path = tmp_path / "junk.lcmlog"
    path.write_bytes(bytes(random.Random(1).randrange(256) for _ in range(5000)))
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", path], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "holds no POUR_STATE messages" in r.stderr


def test_log_without_particles_cannot_render(tmp_path):
    path = tmp_path / "noparticles.lcmlog"
    w = lcm.EventLog(str(path), "w", overwrite=True)
    w.write_event(0, channels.STATE, Bus.state(None, 0))
    w.close()
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", path, "--render", tmp_path / "x.gif"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "no POUR_PARTICLES" in r.stderr


def test_render_needs_gif_or_mp4(tmp_path):
    path = tmp_path / "a.lcmlog"
    path.write_bytes(b"")
    r = subprocess.run([sys.executable, "-m", "pour.lcmlog", path, "--render", tmp_path / "x.avi"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--render wants a .gif or .mp4" in r.stderr


def test_log_replays_onto_the_bus_and_analyses_the_same(recorded, tmp_path):
    log, _, _ = recorded
    player = LOGGER.parent / "lcm-logplayer"
    u = url(32)
    again = tmp_path / "replayed.lcmlog"
    logger = subprocess.Popen([LOGGER, "-q", "-f", f"--lcm-url={u}", again])
    try:
        time.sleep(0.5)  # the logger subscribes before the player starts
        r = subprocess.run([player, f"--lcm-url={u}", "--speed=0.25", log], capture_output=True, text=True,
                           timeout=120)
        assert r.returncode == 0, r.stderr
        time.sleep(0.5)
    finally:
        logger.send_signal(signal.SIGINT)
        logger.wait(timeout=10)
    first, second = lcmlog.analyse(log, None)["_log"], lcmlog.analyse(again, None)["_log"]
    (a,), (b,) = first.episodes, second.episodes
    # UDP may drop a few replayed messages, but what arrives is the same pour, state for state.
    assert len(b.seq) >= 0.9 * len(a.seq)
    va, vb = dict(zip(a.seq, zip(a.theta, a.v))), dict(zip(b.seq, zip(b.theta, b.v)))
    assert all(vb[k] == va[k] for k in vb)
