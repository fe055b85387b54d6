# SPDX-License-Identifier: MIT
"""Shared by the LCM tests: per-process URLs, the controller process, waiting for messages."""
from __future__ import annotations

import os
import signal
import subprocess
import sysconfig
import time
from pathlib import Path
from typing import Callable

import lcm

from pour.lcm import channels, messages, sensors

msgs = messages.load()

LIQUID_G = 10300
"""Scripted samples weigh 10 L of soymilk (1.03 kg/L) in all."""

LOGGER = Path(sysconfig.get_paths()["purelib"]) / "bin" / "lcm-logger"  # the real binary: it stops on SIGINT


def url(offset: int) -> str:
    """A multicast URL of its own for this test process, so that parallel runs do not hear each other."""
    port = 20000 + (os.getpid() * 7 + offset * 131) % 30000
    return f"udpm://239.255.76.67:{port}?ttl=0"


def binary(build_dir: Path, name: str) -> Path:
    """An executable of the build tree (every program lands in bin/)."""
    p = build_dir / "bin" / name
    assert p.is_file(), f"{name} not built (looked in {p.parent})"
    return p


def compiled_weights(build_dir: Path) -> Path:
    """The weights.h pour_controller was built with (CMake's POUR_WEIGHTS): host_sim must pour with it."""
    cache = (build_dir / "CMakeCache.txt").read_text()
    for line in cache.splitlines():
        if line.startswith("POUR_WEIGHTS:"):
            return Path(line.split("=", 1)[1])
    raise AssertionError(f"POUR_WEIGHTS not in {build_dir / 'CMakeCache.txt'}")


class Proc:
    """A child process that is always stopped (SIGINT, then SIGKILL) when the block ends."""

    def __init__(self, argv: list[str]):
        self.argv = [str(a) for a in argv]
        self.p: subprocess.Popen | None = None
        self.out = ""
        self.err = ""

    def __enter__(self) -> "Proc":
        self.p = subprocess.Popen(self.argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        return self

    def stop(self, timeout: float = 10.0) -> int:
        assert self.p is not None
        if self.p.poll() is None:
            self.p.send_signal(signal.SIGINT)
        try:
            self.out, self.err = self.p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.p.kill()
            self.out, self.err = self.p.communicate()
        return self.p.returncode

    def __exit__(self, *exc) -> None:
        if self.p is not None and self.p.returncode is None:
            self.stop()


class Plant:
    """A damped bucket that moves with the controller's torque, so that scripted samples are physical (the
    controller's supervisor calls a bucket that never moves under torque a frozen encoder). Per asked sample:
    θ̇ ← 0.9 θ̇ + 6e-6 rad/s per Q15 LSB of the last answer's torque (≤ 2 rad/s), θ += θ̇ · 1 ms; added to
    what a test asks with."""

    def __init__(self) -> None:
        self.theta = 0.0
        self.omega = 0.0
        self.torque_q15 = 0

    def advance(self) -> tuple[float, float]:
        self.omega = 0.9 * self.omega + 6e-6 * self.torque_q15
        self.theta += self.omega * 1e-3
        return self.theta, self.omega


class Bus:
    """An LCM instance that records what arrives on the channels it is asked to watch."""

    def __init__(self, u: str):
        self.lc = lcm.LCM(u)
        self.got: dict[str, list[bytes]] = {}
        self.plant = Plant()

    def watch(self, channel: str) -> None:
        self.got.setdefault(channel, [])
        self.lc.subscribe(channel, lambda ch, data: self.got[ch].append(data))

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            self.lc.handle_timeout(max(1, int(left * 1000)))

    def wait_for(self, pred: Callable[[], bool], seconds: float) -> bool:
        end = time.monotonic() + seconds
        while not pred():
            left = end - time.monotonic()
            if left <= 0:
                return False
            self.lc.handle_timeout(max(1, min(50, int(left * 1000))))
        return True

    def state(self, seq: int, episode: int = 0, theta: float = 0.1, v: tuple[float, float] = (1.0, 0.0),
              **raw: int) -> bytes:
        """A POUR_SENSORS sample of a bucket at tilt theta [rad] holding the fractions v (rotating, target) of
        LIQUID_G; raw= encoder, scale_rotating_g, scale_target_g override the readings as given (bad input)."""
        m = msgs.sensor_sample_t()
        m.utime, m.seq, m.episode = seq * 1000, seq, episode
        m.encoder = sensors.encoder_count(theta)
        m.scale_rotating_g, m.scale_target_g = round(v[0] * LIQUID_G), round(v[1] * LIQUID_G)
        for k, value in raw.items():
            setattr(m, k, value)
        return m.encode()

    def ask(self, seq: int, seconds: float = 5.0, **kw) -> "msgs.torque_t":
        """Publishes a sample (again every 100 ms, as host_sim does) and waits for the torque answering it."""
        if channels.TORQUE not in self.got:
            self.watch(channels.TORQUE)
        dtheta, _ = self.plant.advance()
        kw = dict(kw, theta=kw.get("theta", 0.1) + dtheta)
        data = self.state(seq, **kw)
        episode = kw.get("episode", 0)

        def answers() -> list:
            return [t for t in map(msgs.torque_t.decode, self.got[channels.TORQUE])
                    if t.seq == seq and t.episode == episode]

        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.lc.publish(channels.SENSORS, data)
            if self.wait_for(lambda: bool(answers()), min(0.1, end - time.monotonic())):
                self.plant.torque_q15 = answers()[-1].torque_q15
                return answers()[-1]
        raise AssertionError(f"no answer on {channels.TORQUE} to seq {seq} within {seconds} s")

    def wait_up(self, seconds: float = 5.0) -> None:
        """Waits for the controller's first status (it publishes one as it starts)."""
        if channels.STATUS not in self.got:
            self.watch(channels.STATUS)
        assert self.wait_for(lambda: bool(self.got[channels.STATUS]), seconds), "controller did not start"

    def last_status(self) -> "msgs.controller_status_t":
        return msgs.controller_status_t.decode(self.got[channels.STATUS][-1])

    def command(self, estop: bool = False, clear_faults: bool = False, stop: bool = False, reset: bool = False) -> None:
        m = msgs.command_t()
        m.utime, m.estop, m.clear_faults = int(time.time() * 1e6), estop, clear_faults
        m.stop, m.reset = stop, reset
        self.lc.publish(channels.COMMAND, m.encode())


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


def record_pour(build_dir: Path, log: Path, u: str, seconds: float = 2, seed: int = 3) -> tuple[Path, str]:
    """One lockstep pour through pour_controller, recorded with lcm-logger into log: (log, host_sim's stdout)."""
    logger = subprocess.Popen([LOGGER, "-q", "-f", f"--lcm-url={u}", log])
    try:
        with Proc([binary(build_dir, "pour_controller"), "--io", f"lcm:{u}", "--lockstep"]) as c:
            bus = Bus(u)
            bus.wait_up()
            r = subprocess.run([binary(build_dir, "host_sim"), "--policy", compiled_weights(build_dir),
                                "--set", f"episode_s={seconds}", "--seed", str(seed), "--lcm", u],
                               capture_output=True, text=True, timeout=120)
            assert r.returncode == 0, r.stderr
            wait_until_still(log)
            c.stop()
    finally:
        logger.send_signal(signal.SIGINT)
        logger.wait(timeout=10)
    return log, r.stdout
