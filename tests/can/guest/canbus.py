# SPDX-License-Identifier: MIT
"""The bench side of the pour CAN protocol for the guest tests: raw AF_CAN sockets (Python's own), frames
encoded and decoded with cantools from can/pour.dbc, so the C codec is checked against the DBC here too."""
from __future__ import annotations

import os
import select
import signal
import socket
import struct
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import math

import cantools

SOURCE_DIR = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[3]))
BUILD_DIR = Path(os.environ.get("POUR_BUILD_DIR", SOURCE_DIR / "build" / "host"))
DBC = SOURCE_DIR / "can" / "pour.dbc"
IFACE = "vcan0"
FRAME = struct.Struct("=IB3x8s")
ENCODER_BITS = 17  # the controller's default
LIQUID_G = 10300   # 10 L of soymilk


def encoder_count(theta_urad: float) -> int:
    """What the 17-bit absolute encoder reads at tilt theta (0 upright; below upright wraps)."""
    return round(theta_urad * 1e-6 * (1 << ENCODER_BITS) / (2 * math.pi)) % (1 << ENCODER_BITS)


class Plant:
    """A damped bucket that moves with the controller's torque, so that scripted samples are physical: the
    controller's supervisor calls a bucket that never moves under torque a frozen encoder. Per sample:
    θ̇ ← 0.9 θ̇ + 6 µrad/s per Q15 LSB of the last torque (≤ 2 rad/s), θ += θ̇ · 1 ms; added to what a test
    sends."""

    def __init__(self) -> None:
        self.theta_urad = 0.0
        self.omega_urad_s = 0.0
        self.torque_q15 = 0

    def advance(self) -> tuple[int, int]:
        self.omega_urad_s = 0.9 * self.omega_urad_s + 6.0 * self.torque_q15
        self.theta_urad += self.omega_urad_s / 1000.0
        return round(self.theta_urad), round(self.omega_urad_s)


@dataclass
class Frame:
    t: float
    id: int
    data: bytes


class Bus:
    def __init__(self, iface: str = IFACE) -> None:
        self.db = cantools.database.load_file(str(DBC))
        self.sock = socket.socket(socket.PF_CAN, socket.SOCK_RAW, socket.CAN_RAW)
        self.sock.bind((iface,))
        self.log: list[Frame] = []
        self.plant = Plant()

    def close(self) -> None:
        self.sock.close()

    def send_raw(self, frame_id: int, data: bytes) -> None:
        self.sock.send(FRAME.pack(frame_id, len(data), data.ljust(8, b"\0")))

    def send(self, name: str, node: int = 0, **signals) -> None:
        m = self.db.get_message_by_name(name)
        self.send_raw((node << 5) | m.frame_id, m.encode(signals, scaling=False))

    def send_sample(self, seq: int, theta_urad: int = 0, rot_g: int = LIQUID_G, tgt_g: int = 0, node: int = 0,
                    encoder: int | None = None) -> None:
        """One Sensors frame: the encoder at the plant's tilt plus theta_urad (or the raw count given), the
        scales as given [g]."""
        dtheta, _ = self.plant.advance()
        count = encoder_count(theta_urad + dtheta) if encoder is None else encoder
        self.send("Sensors", node, Seq=seq & 0xFF, Encoder=count, ScaleRotating=rot_g, ScaleTarget=tgt_g)

    def recv(self, timeout: float) -> Frame | None:
        """The next frame, or None if none arrives within timeout."""
        r, _, _ = select.select([self.sock], [], [], max(0.0, timeout))
        if not r:
            return None
        can_id, dlc, data = FRAME.unpack(self.sock.recv(16))
        f = Frame(time.monotonic(), can_id, data[:dlc])
        self.log.append(f)
        return f

    def poll(self, timeout: float) -> list[Frame]:
        """All frames that arrive within timeout."""
        got = []
        end = time.monotonic() + timeout
        while (f := self.recv(end - time.monotonic())) is not None:
            got.append(f)
        return got

    def wait_for(self, name: str, pred=lambda d: True, timeout: float = 2.0, node: int = 0) -> dict:
        """Waits for the first frame of message name whose raw signals satisfy pred."""
        m = self.db.get_message_by_name(name)
        end = time.monotonic() + timeout
        while (f := self.recv(end - time.monotonic())) is not None:
            if f.id == (node << 5) | m.frame_id:
                d = m.decode(f.data, scaling=False, decode_choices=False)
                if name == "Torque":
                    self.plant.torque_q15 = d["Torque"]
                if pred(d):
                    return d
        raise AssertionError(f"no {name} frame matching the condition within {timeout} s")

    def decode(self, f: Frame) -> tuple[str, dict]:
        m = self.db.get_message_by_frame_id(f.id & 0x1F)
        return m.name, m.decode(f.data, scaling=False, decode_choices=False)


class Controller:
    """pour_controller --io can:vcan0,... as a child process (program: pour_controller_sim for drive=sim)."""

    def __init__(self, *args: str, io: str = f"can:{IFACE},heartbeat-ms=10", program: str = "pour_controller") -> None:
        exe = BUILD_DIR / "bin" / program
        if not exe.exists():
            raise FileNotFoundError(f"{exe} not built")
        self.proc = subprocess.Popen([str(exe), "--io", io, *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True)

    def stop(self) -> str:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        out, err = self.proc.communicate(timeout=20)
        assert self.proc.returncode == 0, f"controller exit {self.proc.returncode}: {err}"
        return out + err
