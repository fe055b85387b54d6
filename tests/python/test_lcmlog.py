# SPDX-License-Identifier: MIT
"""A pour recorded by lcm-logger replays into pour-lcmlog: the summary matches host_sim's own, the
plots and the render are written; bad logs give clear errors."""
import json
import random
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import lcm
import pytest

from conftest import BUILD_DIR
from lcm_helpers import LOGGER, Bus, msgs, record_pour, url
from pour.lcm import channels, logfile, sensors

def summary_line(text: str) -> str:
    return [x for x in text.splitlines() if x.startswith("summary")][0]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """One lockstep pour (2 s) through pour_controller, recorded with lcm-logger."""
    tmp = tmp_path_factory.mktemp("log")
    log, stdout = record_pour(BUILD_DIR, tmp / "pour.lcmlog", url(31))
    return log, stdout, tmp


def test_log_summary_matches_the_simulated_pour(recorded):
    log, host_out, tmp = recorded
    out = tmp / "plots"
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", log, "--out", out, "--json"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    (ep,) = s["episodes"]
    # host_sim's summary: poured/spilled after the last step; the log's last state is one step earlier.
    line = summary_line(host_out)
    poured = float(re.search(r"poured\s+([\d.]+) %", line).group(1)) / 100
    spilled = float(re.search(r"spilled\s+([\d.]+) %", line).group(1)) / 100
    assert abs(ep["poured_pct"] / 100 - poured) <= 1 / 150 + 1e-9
    assert abs(ep["spilled_pct"] / 100 - spilled) <= 1 / 150 + 1e-9
    # UDP multicast to the logger may drop a few datagrams on a loaded machine, anywhere in the stream
    # (the end included), samples and answers alike.
    assert ep["first_seq"] <= 100 and ep["last_seq"] >= 1900
    assert s["samples"] >= 1900 and s["unanswered"] <= 100
    assert s["latency_us"]["n"] == s["samples"] - s["unanswered"] and s["latency_us"]["median"] > 0
    assert s["particle_frames"] > 0 and s["undecodable"] == {} and s["refused"] == {}
    assert ep["source"] == channels.TRUTH
    # The tools read the encoder as the simulator writes it: every logged count is the count of the true
    # tilt of the same sample (round(θ·2^17/2π) mod 2^17).
    (e,) = logfile.read_log(log).episodes
    both = [k for k in e.raw if k in e.truth]
    assert len(both) >= 1900
    assert all(sensors.encoder_count(e.truth[k][0]) == e.raw[k][0] for k in both)
    for png in ("traces.png", "latency.png"):
        assert (out / png).stat().st_size > 10000
    assert json.loads((out / "summary.json").read_text())["episodes"] == s["episodes"]


def test_log_text_output_reads_like_host_sim(recorded):
    log, host_out, _ = recorded
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", log], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert summary_line(r.stdout).startswith("summary (1 episode): poured ")
    assert "latency POUR_SENSORS -> POUR_TORQUE: median" in r.stdout
    assert "controller: mode" in r.stdout
    assert "plant from POUR_TRUTH" in r.stdout  # host_sim publishes the simulated plant's truth


def test_log_renders_like_host_sim(recorded):
    log, _, tmp = recorded
    gif = tmp / "replay.gif"
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", log, "--render", gif], capture_output=True, text=True,
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
        w.write_event(k * 1000, channels.SENSORS, bus_state(None, k, theta=0.01 * k))
        t = msgs.torque_t()
        t.seq, t.torque = k, 1.0
        w.write_event(k * 1000 + 80, channels.TORQUE, t.encode())
        w.write_event(k * 1000 + 90, channels.TORQUE, bytes(rng.randrange(256) for _ in range(30)))
    w.write_event(30000, channels.SENSORS, msgs.command_t().encode())
    w.write_event(30001, "SOMEONE_ELSE", b"ignored")
    w.close()
    s = logfile.analyse(path, None)
    assert s["undecodable"] == {channels.TORQUE: 20, channels.SENSORS: 1}
    assert s["samples"] == 20 and s["unanswered"] == 0
    assert s["latency_us"]["median"] == 80


def test_missing_log_is_a_clear_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", tmp_path / "nope.lcmlog"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "no such log file" in r.stderr


def test_garbage_file_is_a_clear_error(tmp_path):
    path = tmp_path / "junk.lcmlog"
    path.write_bytes(bytes(random.Random(1).randrange(256) for _ in range(5000)))
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "holds no usable POUR_SENSORS messages" in r.stderr


def test_log_without_particles_cannot_render(tmp_path):
    path = tmp_path / "noparticles.lcmlog"
    w = lcm.EventLog(str(path), "w", overwrite=True)
    w.write_event(0, channels.SENSORS, Bus.state(None, 0))
    w.close()
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path, "--render", tmp_path / "x.gif"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "no POUR_PARTICLES" in r.stderr


def test_render_needs_gif_or_mp4(tmp_path):
    path = tmp_path / "a.lcmlog"
    path.write_bytes(b"")
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path, "--render", tmp_path / "x.avi"],
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
    first, second = logfile.analyse(log, None)["_log"], logfile.analyse(again, None)["_log"]
    (a,), (b,) = first.episodes, second.episodes
    # UDP may drop a few replayed messages, but what arrives is the same pour, state for state.
    assert len(b.seq) >= 0.9 * len(a.seq)
    assert len(b.series_seq) >= 0.9 * len(a.series_seq)
    va, vb = dict(zip(a.series_seq, zip(a.theta, a.v))), dict(zip(b.series_seq, zip(b.theta, b.v)))
    assert all(vb[k] == va[k] for k in vb)
    assert {k: b.raw[k] for k in b.raw} == {k: a.raw[k] for k in b.raw}  # the raw samples too


def sensor_log(path: Path, samples, truth=()) -> None:
    """A log of scripted POUR_SENSORS samples (seq, theta, (v_rot, v_tgt), raw overrides) and POUR_TRUTH."""
    w = lcm.EventLog(str(path), "w", overwrite=True)
    for seq, theta, v, raw in samples:
        w.write_event(seq * 1000, channels.SENSORS, Bus.state(None, seq, theta=theta, v=v, **raw))
    for seq, values in truth:
        g = msgs.plant_truth_t()
        g.seq = seq
        g.theta, g.omega, g.v_rotating, g.v_target, g.v_spill = values
        w.write_event(seq * 1000 + 1, channels.TRUTH, g.encode())
    w.close()


def test_log_without_truth_reads_the_plant_from_the_sensors(tmp_path):
    """A rig's log has no POUR_TRUTH: θ from the encoder count, the volumes from the scales (V = m/m0, the
    rest spilled or in flight), as the firmware's estimator defines them."""
    path = tmp_path / "rig.lcmlog"
    # 10 L pour: 60 % moves to the target, 5 % goes missing; the bucket tilts to 100° and back below upright.
    sensor_log(path, [(0, 0.0, (1.0, 0.0), {}), (1, 1.75, (0.5, 0.4), {}), (2, -0.02, (0.35, 0.6), {})])
    s = logfile.analyse(path, None)
    (ep,) = s["episodes"]
    assert ep["source"].startswith(channels.SENSORS)
    assert ep["poured_pct"] == pytest.approx(60, abs=1e-2) and ep["spilled_pct"] == pytest.approx(5, abs=1e-2)
    assert ep["left_pct"] == pytest.approx(35, abs=1e-2)
    assert ep["max_theta_deg"] == pytest.approx(100.27, abs=0.01)  # 1.75 rad to one count (47.9 µrad)
    log = s["_log"]
    assert log.episodes[0].theta[-1] == pytest.approx(-0.02, abs=5e-5)  # below upright: the count wrapped


def test_log_prefers_truth_and_refuses_impossible_values(tmp_path):
    path = tmp_path / "mixed.lcmlog"
    sensor_log(path, [(0, 0.0, (1.0, 0.0), {}), (1, 0.1, (0.9, 0.1), {}),
                      (2, 0.2, (0.8, 0.2), {"encoder": 1 << 17}),  # no count of a 17-bit encoder
                      (3, 0.2, (0.8, 0.2), {"encoder": -1})],
               truth=[(0, (0.0, 0.0, 1.0, 0.0, 0.0)), (1, (0.1, 1.0, 0.7, 0.25, 0.05)),
                      (2, (float("nan"), 0.0, 0.5, 0.5, 0.0)), (3, (0.2, float("inf"), 0.5, 0.5, 0.0))])
    s = logfile.analyse(path, None)
    (ep,) = s["episodes"]
    assert ep["source"] == channels.TRUTH and ep["samples"] == 4
    assert ep["poured_pct"] == pytest.approx(25) and ep["spilled_pct"] == pytest.approx(5)  # the last plausible truth
    assert s["refused"] == {channels.SENSORS: 2, channels.TRUTH: 2}
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and "refused 4" in r.stdout
    # The same samples read as a 24-bit encoder's: 2^17 is then a count like any other.
    assert logfile.analyse(path, None, encoder_bits=24)["refused"] == {channels.SENSORS: 1, channels.TRUTH: 2}


def test_log_without_liquid_on_the_scales_is_a_clear_error(tmp_path):
    path = tmp_path / "empty.lcmlog"
    sensor_log(path, [(0, 0.0, (0.0, 0.0), {}), (1, 0.1, (0.0, 0.0), {})])
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "weighs 0 g of liquid" in r.stderr


@pytest.mark.parametrize("bits", ["7", "25"])
def test_bad_encoder_bits_is_a_clear_error(tmp_path, bits):
    path = tmp_path / "a.lcmlog"
    path.write_bytes(b"")
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path, "--encoder-bits", bits], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "--encoder-bits must be 8 .. 24" in r.stderr


def test_sensor_readings_in_physical_units_and_their_bad_input():
    assert sensors.encoder_count(0.0) == 0 and sensors.encoder_count(-1e-4) == (1 << 17) - 2
    assert sensors.encoder_angle(1 << 15) == pytest.approx(3.141592653589793 / 2)
    assert sensors.encoder_angle((1 << 17) - 2) == pytest.approx(-2 * 2 * 3.141592653589793 / (1 << 17))
    assert sensors.volumes(5150, 4120, 10300) == pytest.approx((0.5, 0.4, 0.1))
    assert sensors.volumes(9000, 2000, 10300)[2] == 0.0  # more than m0 on the scales: nothing missing
    with pytest.raises(ValueError, match="outside 0 .. 2"):
        sensors.encoder_angle(1 << 17)
    with pytest.raises(ValueError, match="outside 0 .. 2"):
        sensors.encoder_angle(-1)
    with pytest.raises(ValueError, match="not finite"):
        sensors.encoder_count(float("nan"))
    with pytest.raises(ValueError, match="must be positive"):
        sensors.volumes(1, 1, 0)


def test_lost_samples_are_warned_about(tmp_path):
    """Samples missing between the first and the last seq (gaps) are named on stderr, in text and JSON mode."""
    path = tmp_path / "gappy.lcmlog"
    sensor_log(path, [(0, 0.0, (1.0, 0.0), {}), (1, 0.5, (0.9, 0.1), {}), (4, 1.0, (0.5, 0.5), {})])
    for extra in ([], ["--json"]):
        r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path, *extra], capture_output=True, text=True,
                           timeout=120)
        assert r.returncode == 0, r.stderr
        assert "pour-lcmlog: warning: episode 1: 2 of the samples 0..4 are not in the log" in r.stderr, r.stderr
    assert json.loads(r.stdout)["episodes"][0]["poured_pct"] == pytest.approx(50)
    sensor_log(path, [(0, 0.0, (1.0, 0.0), {}), (1, 0.5, (0.9, 0.1), {}), (2, 1.0, (0.5, 0.5), {})])
    r = subprocess.run([sys.executable, "-m", "pour.lcm.logfile", path], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr


def test_the_controllers_faults_are_printed_by_name(monkeypatch):
    from pour import functions, libpoursim
    from pour.lcm import logfile
    assert logfile._fault_text(0) == "none"
    assert logfile._fault_text(0x0002 | 0x0800) == "ESTOP, DRIVE (0x0802)"

    def no_library(faults):
        raise libpoursim.SimError("libpoursim.so not found")

    monkeypatch.setattr(functions, "fault_names", no_library)
    assert logfile._fault_text(0x0002) == "0x0002 (names: libpoursim not found)"
