# SPDX-License-Identifier: MIT
"""A bench's view of pour controllers on a CAN bus: python-can moves the frames, cantools decodes them with
can/pour.dbc (the one source of truth: message layouts, fault names, modes, parameter names and results).

    bus = Bench(channel="vcan0")            # python-can, interface socketcan by default
    nodes = bus.scan()                      # {node_id: NodeState}; two nodes on one id: DuplicateNodeError
    n = bus.node(0)
    n.info()                                # NodeState: mode, faults by name, identity (policy hash, tau_max)
    n.set("omega_max", 1500000); n.save()   # ParamValue or ParamAck; a refusal: ParamRefused (its reason)
    n.estop(); n.clear(); n.record("run.log", seconds=5)

Every wait has a timeout; a node that does not answer raises NodeTimeout, which carries its last state.
"""
from __future__ import annotations

import errno
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import can
import cantools

from pour import atomic
from pour.can import dbc

DEFAULT_TIMEOUT_S = 1.0
START_TRIES = 5  # identify: a Stop and a start that missed one tick are sent again
REST_S = 1.0  # identify: recorded after the end
# pour/experiment.h's phases: Torque.Action while an experiment runs, and how it ended (8, 9) after it.
EXPERIMENT_PHASES = {1: "ramp", 2: "steps", 3: "chirp", 4: "back", 5: "tilt", 6: "dwell", 7: "return", 8: "done",
                     9: "out of range", 10: "sweep"}
EXPERIMENT_ENDED = 8  # Action >= this outside RUN: the experiment is over
HEARTBEAT_WAIT_S = 0.5  # five heartbeat periods of the default 100 ms
CALIBRATION_S = 30.0  # calibrate: the outcome's wait (the board's sequence takes 3.1 s)
# Why a CalibrationResult's Status is not OK (names as the DBC's value table gives them; a status this table
# does not know is still shown by its DBC name).
CALIBRATION_REASONS = {
    "REFUSED_RUNNING": "the controller runs: stop it first",
    "REFUSED_ESTOP": "the e-stop is asserted: release and clear it first",
    "UNAVAILABLE": "this controller has no drive of its own to measure (pour_controller_sim --io "
                   "can:IFACE,drive=sim simulates one)",
    "BAD_RESISTANCE": "the phase resistance is out of range or unequal on the two axes (an open phase?)",
    "BAD_INDUCTANCE": "the phase inductance is out of range",
    "NO_ENCODER": "the motor encoder did not count over an electrical turn (unplugged?)",
    "BAD_POLE_PAIRS": "the counts of an electrical turn fit no pole-pair count 1..32",
    "MOTION_RANGE": "the output moved beyond the sequence's range: stopped there",
    "ABORTED": "a fault, the e-stop or a stop ended it, or a latched drive fault refused it",
    "WRITE_FAILED": "measured, but the flash refused it: no valid calibration stored",
    "REFUSED_NOT_UPRIGHT": "the output is not within 5 deg of upright: bring the bucket upright first",
    "REFUSED_NOT_EMPTY": "the rotating scale reads more than 200 g beyond its tare: empty the bucket first",
    "REFUSED_NO_SENSORS": "no sensor sample in the last 20 ms: start the rig's sensor node first",
}
TARE_ROTATING = 1
TARE_TARGET = 2


class BenchError(Exception):
    """Anything the bench cannot do; the message says what and why."""


class NoNodeError(BenchError):
    pass


class DuplicateNodeError(BenchError):
    pass


class NodeTimeout(BenchError):
    def __init__(self, message: str, last: "NodeState | None") -> None:
        super().__init__(message)
        self.last = last


class CommandRefused(BenchError):
    """The node counted the command as refused (the heartbeat's Refused moved): it changed nothing."""


class ParamRefused(BenchError):
    def __init__(self, message: str, param: str, result: str) -> None:
        super().__init__(message)
        self.param = param
        self.result = result


class CalibrationFailed(BenchError):
    """A CalibrationStart refused, or a calibration that did not end OK; .result says what the node sent."""

    def __init__(self, message: str, result: "Calibration") -> None:
        super().__init__(message)
        self.result = result


@dataclass
class Calibration:
    """A CalibrationResult: the request's status and the calibration stored in flash (read back by the node)."""
    status: str
    stored: str
    resistance_ohm: float
    inductance_mh: float
    pole_pairs: int
    encoder_reversed: bool
    electrical_offset_deg: float

    def describe(self) -> str:
        if self.stored != "OK":
            return f"stored calibration: {self.stored}"
        direction = "reversed" if self.encoder_reversed else "normal"
        return (f"resistance {self.resistance_ohm:.3f} Ohm, inductance {self.inductance_mh:.3f} mH, pole pairs "
                f"{self.pole_pairs}, encoder direction {direction}, electrical offset "
                f"{self.electrical_offset_deg:.1f} deg (stored {self.stored})")


@dataclass
class Identity:
    weights_hash: int
    tau_max_nm: float
    fw_version: int
    init_status: int


@dataclass
class DriveTelemetry:
    """The drive's last DriveTelemetry frame: the current loop's d and q currents [A], the bus voltage [V] and
    its latched faults, by the DBC's names (Overcurrent, ...)."""
    id_a: float
    iq_a: float
    vbus_v: float
    faults: list[str]

    def describe(self) -> str:
        return (f"drive faults {', '.join(self.faults) or 'none'}, Iq {self.iq_a:.3f} A, Id {self.id_a:.3f} A, "
                f"bus {self.vbus_v:.2f} V")


def drive_fault_signals(db: cantools.database.can.Database) -> list[str]:
    """DriveTelemetry's fault signals (DriveFault_*), in the DBC's order (bit 0 first)."""
    return [s.name for s in db.get_message_by_name("DriveTelemetry").signals if s.name.startswith("DriveFault_")]


def drive_telemetry(db: cantools.database.can.Database, sig: dict) -> DriveTelemetry:
    """A DriveTelemetry frame's raw signals (Decoder.decode) in SI units, by the DBC's scales."""
    m = db.get_message_by_name("DriveTelemetry")
    scaled = {n: sig[n] * m.get_signal_by_name(n).scale for n in ("Id", "Iq", "Vbus")}
    return DriveTelemetry(scaled["Id"], scaled["Iq"], scaled["Vbus"],
                          [f.removeprefix("DriveFault_") for f in drive_fault_signals(db) if sig[f]])


@dataclass
class NodeState:
    """What a node last said of itself (monotonic times [s])."""
    node_id: int
    mode: str = "?"
    faults: list[str] = field(default_factory=list)
    rx_dropped: int = 0
    overruns: int = 0
    refused: int = 0  # commands refused or dropped by the node, mod 16 (Heartbeat.Refused)
    held: bool = False  # no run armed: after the board's boot or a Stop, RUN waits for a Reset (Heartbeat.Held)
    counter: int | None = None
    identity: Identity | None = None
    t_heartbeat: float | None = None
    heartbeats: int = 0
    counter_breaks: int = 0  # heartbeats whose counter repeated or went back: another node on this id
    identities: set[int] = field(default_factory=set)  # distinct policy hashes seen on this id
    drive: DriveTelemetry | None = None  # the last DriveTelemetry (a node with a drive of its own sends one a heartbeat)

    def describe(self, now: float | None = None) -> str:
        now = time.monotonic() if now is None else now
        age = f"{now - self.t_heartbeat:.2f} s ago" if self.t_heartbeat is not None else "never"
        faults = ", ".join(self.faults) or "none"
        return f"node {self.node_id}: mode {self.mode}, faults {faults}, last heartbeat {age}"


def fault_signals(db: cantools.database.can.Database) -> list[str]:
    """The heartbeat's fault signals, in bit order (names as the DBC gives them, without "Fault_")."""
    hb = db.get_message_by_name("Heartbeat")
    return [s.name for s in sorted(hb.signals, key=lambda s: s.start) if s.name.startswith("Fault_")]


def load_dbc(path: Path | None = None) -> cantools.database.can.Database:
    """The protocol's DBC: path, or the one pour.can.dbc finds (the checkout's or the package's)."""
    return cantools.database.load_file(str(path if path is not None else dbc.default_dbc()))


def param_names(db: cantools.database.can.Database) -> dict[int, str]:
    """Parameter id -> name, from ParamId's value table (the firmware's table, firmware/include/pour/params.h)."""
    pid = db.get_message_by_name("ParamRead").get_signal_by_name("ParamId")
    return {int(k): str(v) for k, v in sorted(pid.choices.items())}


class Decoder:
    """Frames -> (node id, message name, raw signals) by the DBC; None for a frame it does not know."""

    def __init__(self, db: cantools.database.can.Database) -> None:
        self._by_cmd = {m.frame_id: m for m in db.messages}

    def decode(self, msg: can.Message) -> tuple[int, str, dict] | None:
        if msg.is_extended_id or msg.is_error_frame or msg.is_remote_frame:
            return None
        node_id, cmd = msg.arbitration_id >> dbc.NODE_SHIFT, msg.arbitration_id & dbc.CMD_MASK
        m = self._by_cmd.get(cmd)
        if m is None or len(msg.data) != m.length:
            return None
        try:
            return node_id, m.name, m.decode(bytes(msg.data), scaling=False, decode_choices=False)
        except cantools.database.errors.DecodeError:
            return None


# Where a user without CAN hardware is sent (docs/bench.md's section of that name).
NO_CAN_DOC = 'docs/bench.md, "No CAN hardware"'


def _no_bus_hint(e: Exception, channel: str) -> str:
    """What to do when a bus does not open for want of SocketCAN or of the interface; "" otherwise."""
    err = getattr(e, "errno", None)
    if err == errno.EAFNOSUPPORT:
        return (f": this kernel has no SocketCAN; without CAN hardware use a vcan interface or the user-mode "
                f"Linux guest the tests use ({NO_CAN_DOC}), or --interface virtual")
    if err in (errno.ENODEV, errno.ENXIO):
        return (f": no interface {channel}; for a virtual one: ip link add dev {channel} type vcan && "
                f"ip link set up {channel} ({NO_CAN_DOC})")
    return ""


class Bench:
    """One CAN bus. channel/interface are python-can's; bus: an open python-can bus instead."""

    def __init__(self, channel: str = "vcan0", interface: str = "socketcan", bus: can.BusABC | None = None,
                 dbc_path: Path | None = None) -> None:
        self.db = load_dbc(dbc_path)
        try:
            self.protocol = dbc.protocol_version(self.db.version)
        except ValueError as e:
            raise BenchError(str(e)) from e
        self.channel = channel
        try:
            self.bus = bus if bus is not None else can.Bus(interface=interface, channel=channel)
        except (OSError, can.CanError, ValueError) as e:
            raise BenchError(f"cannot open CAN bus {interface}:{channel}: {e}{_no_bus_hint(e, channel)}") from e
        self.states: dict[int, NodeState] = {}
        self._by_cmd = {m.frame_id: m for m in self.db.messages}
        self.decoder = Decoder(self.db)
        self._faults = fault_signals(self.db)
        self._listeners: list[Callable[[can.Message], None]] = []
        self.param_names = param_names(self.db)
        self.param_ids = {v: k for k, v in self.param_names.items()}

    def close(self) -> None:
        self.bus.shutdown()

    def __enter__(self) -> "Bench":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- frames ------------------------------------------------------------------------------------------
    def message(self, cmd_or_name: int | str):
        return self.db.get_message_by_name(cmd_or_name) if isinstance(cmd_or_name, str) else self._by_cmd[cmd_or_name]

    def send(self, node_id: int, name: str, **signals: int) -> None:
        m = self.db.get_message_by_name(name)
        data = m.encode(signals, scaling=False, strict=True) if m.signals else b""
        try:
            self.bus.send(can.Message(arbitration_id=dbc.can_id(node_id, m.frame_id), data=data,
                                      is_extended_id=False))
        except can.CanError as e:
            raise BenchError(f"cannot send {name} to node {node_id} on {self.channel}: {e}") from e

    def decode(self, msg: can.Message) -> tuple[int, str, dict] | None:
        return self.decoder.decode(msg)

    def _note(self, msg: can.Message) -> tuple[int, str, dict] | None:
        d = self.decode(msg)
        if d is None:
            return None
        node_id, name, sig = d
        now = time.monotonic()
        if name == "Heartbeat":
            st = self.states.setdefault(node_id, NodeState(node_id))
            # One node's counter only moves forward (1, or a little more past lost frames); two nodes on one id
            # interleave two counters, so that at least every other step repeats one or goes back.
            if st.counter is not None and ((sig["Counter"] - st.counter) % 256 == 0 or
                                           (sig["Counter"] - st.counter) % 256 >= 128):
                st.counter_breaks += 1
            st.counter = sig["Counter"]
            st.mode = self.message("Heartbeat").get_signal_by_name("Mode").choices.get(sig["Mode"], str(sig["Mode"]))
            st.mode = str(st.mode)
            st.faults = [f.removeprefix("Fault_") for f in self._faults if sig[f]]
            st.rx_dropped, st.overruns, st.refused = sig["RxDropped"], sig["Overruns"], sig["Refused"]
            st.held = bool(sig.get("Held", 0))  # protocol 8 on
            st.t_heartbeat = now
            st.heartbeats += 1
        elif name == "DriveTelemetry":
            self.states.setdefault(node_id, NodeState(node_id)).drive = drive_telemetry(self.db, sig)
        elif name == "Identity":
            st = self.states.setdefault(node_id, NodeState(node_id))
            st.identity = Identity(sig["WeightsHash"], sig["TauMax"] * 0.01, sig["FwVersion"], sig["InitStatus"])
            st.identities.add(sig["WeightsHash"])
        return d

    def frames(self, seconds: float) -> Iterator[can.Message]:
        """Every frame on the bus for the given time (states updated on the way)."""
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            msg = self.bus.recv(timeout=left)
            if msg is None:
                continue
            self._note(msg)
            for cb in self._listeners:
                cb(msg)
            yield msg

    def wait_for(self, node_id: int, pred: Callable[[str, dict], bool], timeout: float, what: str) -> tuple[str, dict]:
        """The first message of node_id satisfying pred(name, signals), else NodeTimeout naming what."""
        for msg in self.frames(timeout):
            d = self.decode(msg)
            if d is not None and d[0] == node_id and pred(d[1], d[2]):
                return d[1], d[2]
        last = self.states.get(node_id)
        state = last.describe() if last else f"node {node_id}: never heard on {self.channel}"
        raise NodeTimeout(f"node {node_id} did not answer {what} within {timeout:g} s ({state})", last)

    # -- nodes -------------------------------------------------------------------------------------------
    def scan(self, seconds: float = HEARTBEAT_WAIT_S) -> dict[int, NodeState]:
        """The nodes whose heartbeats arrive within seconds. NoNodeError if none; DuplicateNodeError if an id
        carries two controllers (two policy hashes, or two heartbeat counters interleaved)."""
        self.states = {}
        for _ in self.frames(seconds):
            pass
        found = {k: v for k, v in sorted(self.states.items()) if v.heartbeats > 0}
        if not found:
            raise NoNodeError(f"no node on {self.channel}: no heartbeat within {seconds:g} s (is the controller "
                              f"running, on this interface, at the bus's bit rate?)")
        for st in found.values():
            if len(st.identities) > 1 or st.counter_breaks >= 2:
                raise DuplicateNodeError(
                    f"two nodes answer on id {st.node_id} of {self.channel} ({len(st.identities)} policy hashes, "
                    f"{st.counter_breaks} of {st.heartbeats} heartbeat counters repeated or went back): give each "
                    f"controller its own node id")
        return found

    def node(self, node_id: int) -> "Node":
        dbc.check_node_id(node_id)
        return Node(self, node_id)


class Node:
    """One controller on the bus."""

    def __init__(self, bench: Bench, node_id: int) -> None:
        self.bench = bench
        self.id = node_id

    @property
    def state(self) -> NodeState | None:
        return self.bench.states.get(self.id)

    def info(self, timeout: float = DEFAULT_TIMEOUT_S) -> NodeState:
        """Waits for a heartbeat and an identity frame of this node."""
        self.bench.wait_for(self.id, lambda n, s: n == "Heartbeat", timeout, "with a heartbeat")
        if self.state is None or self.state.identity is None:
            self.bench.wait_for(self.id, lambda n, s: n == "Identity", timeout, "with its identity")
        assert self.state is not None
        return self.state

    def check_protocol(self, timeout: float = DEFAULT_TIMEOUT_S) -> NodeState:
        """info(), and BenchError unless the node speaks the DBC's protocol: frames whose layout changed
        between versions (CalibrationResult's Stored, in 6) would be misread."""
        st = self.info(timeout)
        assert st.identity is not None
        if st.identity.fw_version != self.bench.protocol:
            raise BenchError(f"node {self.id} runs firmware {st.identity.fw_version}, but this DBC is protocol "
                             f"{self.bench.protocol}: use the DBC of that firmware")
        return st

    # -- commands (no answer of their own: the next heartbeat shows their effect) ---------------------------
    def estop(self, asserted: bool = True) -> None:
        self.bench.send(self.id, "Estop", Assert=1 if asserted else 0)

    def _command(self, message: str, timeout: float) -> NodeState:
        """Sends a command the node may refuse, and waits for the second heartbeat after it (the first may
        have been packed before the tick that took it). CommandRefused if its Refused count moved."""
        before = self.info(timeout)
        refused, counter = before.refused, before.counter
        assert counter is not None
        self.bench.send(self.id, message)
        self.bench.wait_for(self.id, lambda n, s: n == "Heartbeat" and 2 <= (s["Counter"] - counter) % 256 < 128,
                            timeout, f"with two heartbeats after {message}")
        assert self.state is not None
        if self.state.refused != refused:
            raise CommandRefused(f"node {self.id} refused {message} in {self.state.mode} (a Stop outside RUN, a "
                                 "Reset in RUN or during the active stop, a ClearErrors with the e-stop held or "
                                 f"during the active stop): nothing changed ({self.state.describe()})")
        return self.state

    def clear(self, timeout: float = DEFAULT_TIMEOUT_S) -> NodeState:
        return self._command("ClearErrors", timeout)

    def stop(self, timeout: float = DEFAULT_TIMEOUT_S) -> NodeState:
        return self._command("Stop", timeout)

    def reset(self, timeout: float = DEFAULT_TIMEOUT_S) -> NodeState:
        return self._command("Reset", timeout)

    def wait_mode(self, modes: set[str], timeout: float = DEFAULT_TIMEOUT_S) -> NodeState:
        """Waits for a heartbeat whose mode is one of modes."""
        names = self.bench.message("Heartbeat").get_signal_by_name("Mode").choices
        want = {int(k) for k, v in names.items() if str(v) in modes}
        self.bench.wait_for(self.id, lambda n, s: n == "Heartbeat" and s["Mode"] in want, timeout,
                            f"with a heartbeat in {'/'.join(sorted(modes))}")
        assert self.state is not None
        return self.state

    # -- parameters ----------------------------------------------------------------------------------------
    def param_id(self, name_or_id: str | int) -> int:
        if isinstance(name_or_id, int) or str(name_or_id).isdigit():
            return int(name_or_id)
        try:
            return self.bench.param_ids[str(name_or_id)]
        except KeyError:
            raise BenchError(f"no parameter '{name_or_id}' (known: {', '.join(self.bench.param_ids)})") from None

    def _param_name(self, pid: int) -> str:
        return self.bench.param_names.get(pid, f"#{pid}")

    def _request(self, request: str, pid: int, timeout: float, **signals: int) -> dict:
        """Sends a parameter request; returns the ParamValue's signals (read, write) or the ParamAck's (save,
        tare, zero). ParamRefused with the controller's reason; NodeTimeout if it does not answer."""
        cmd = self.bench.message(request).frame_id
        self.bench.send(self.id, request, **signals)

        def answer(name: str, s: dict) -> bool:
            return (name == "ParamValue" and s["ParamId"] == pid) or (
                name == "ParamAck" and s["Request"] == cmd and s["ParamId"] == pid)

        name, s = self.bench.wait_for(self.id, answer, timeout, f"{request}({self._param_name(pid)})"
                                      if request in ("ParamRead", "ParamWrite") else request)
        if name == "ParamAck" and s["Result"] != 0:
            result = str(self.bench.message("ParamAck").get_signal_by_name("Result").choices[s["Result"]])
            what = f"{request} {self._param_name(pid)}" if request in ("ParamRead", "ParamWrite") else request
            reason = {"BUSY": "the controller runs: stop it or let it reach IDLE/FAULT first",
                      "OUT_OF_RANGE": "the value lies outside the parameter's range (firmware/include/pour/params.h)",
                      "UNKNOWN_ID": "this controller has no such parameter",
                      "INCONSISTENT": "the controller refuses the set as a whole (e.g. theta_min >= theta_max)",
                      "NO_STORAGE": "the controller has no storage (pour_controller --io can:IFACE,params=FILE)",
                      "NO_SAMPLE": "no sensor sample has reached the controller yet"}.get(result, "")
            raise ParamRefused(f"node {self.id} refused {what}: {result} ({reason})", self._param_name(pid), result)
        return s

    def get(self, name_or_id: str | int, timeout: float = DEFAULT_TIMEOUT_S) -> int:
        pid = self.param_id(name_or_id)
        return int(self._request("ParamRead", pid, timeout, ParamId=pid)["Value"])

    def set(self, name_or_id: str | int, value: int, timeout: float = DEFAULT_TIMEOUT_S) -> int:
        """Sets a parameter (raw, in its unit); returns the value now in force."""
        pid = self.param_id(name_or_id)
        return int(self._request("ParamWrite", pid, timeout, ParamId=pid, Value=int(value))["Value"])

    def params(self, timeout: float = DEFAULT_TIMEOUT_S) -> dict[str, int]:
        return {name: self.get(pid, timeout) for pid, name in sorted(self.bench.param_names.items())}

    def save(self, timeout: float = DEFAULT_TIMEOUT_S) -> None:
        self._request("ParamSave", 0, timeout)

    def tare(self, scales: int = TARE_ROTATING | TARE_TARGET, timeout: float = DEFAULT_TIMEOUT_S) -> None:
        self._request("Tare", 0, timeout, Scales=scales)

    def zero(self, timeout: float = DEFAULT_TIMEOUT_S) -> None:
        self._request("Zero", 0, timeout)

    # -- calibration ---------------------------------------------------------------------------------------
    def _calibration(self, sig: dict) -> Calibration:
        m = self.bench.message("CalibrationResult")

        def name(signal: str) -> str:
            return str(m.get_signal_by_name(signal).choices.get(sig[signal], sig[signal]))

        def scaled(signal: str) -> float:
            return float(sig[signal] * m.get_signal_by_name(signal).scale)

        return Calibration(name("Status"), name("Stored"), scaled("Resistance"), scaled("Inductance"),
                           int(sig["PolePairs"]), bool(sig["EncoderReversed"]), scaled("ElectricalOffset"))

    def calibrate(self, seconds: float = CALIBRATION_S, timeout: float = DEFAULT_TIMEOUT_S) -> Calibration:
        """Starts the drive's self-calibration (CalibrationStart) and follows it to its outcome: the stored
        calibration when it ends OK. CalibrationFailed names a refusal (the first answer is not MEASURING) or why
        the measurement stopped; NodeTimeout (with the node's last state) if no answer comes within timeout, or
        no outcome within seconds."""
        self.bench.send(self.id, "CalibrationStart")
        _, sig = self.bench.wait_for(self.id, lambda n, s: n == "CalibrationResult", timeout, "CalibrationStart")
        first = self._calibration(sig)
        if first.status != "MEASURING":
            raise CalibrationFailed(f"node {self.id} refused the calibration: {first.status} "
                                    f"({CALIBRATION_REASONS.get(first.status, 'see can/pour.dbc')}); "
                                    f"{first.describe()}", first)
        _, sig = self.bench.wait_for(self.id, lambda n, s: n == "CalibrationResult", seconds,
                                     "with the calibration's outcome")
        done = self._calibration(sig)
        if done.status != "OK":
            raise CalibrationFailed(f"node {self.id}'s calibration failed: {done.status} "
                                    f"({CALIBRATION_REASONS.get(done.status, 'see can/pour.dbc')}); "
                                    f"{done.describe()}", done)
        return done

    def read_calibration(self, timeout: float = DEFAULT_TIMEOUT_S) -> Calibration:
        """Reads the calibration the node stores (CalibrationRead): answered in any mode, it moves nothing,
        starts nothing and is never counted as refused. The answer's status is STORED and its stored field
        the block's state (OK with the values, or EMPTY, CORRUPT, OLD_VERSION, ...). CalibrationFailed if the
        node has no calibration of its own (UNAVAILABLE); NodeTimeout if it does not answer within timeout."""
        status = self.bench.message("CalibrationResult").get_signal_by_name("Status").choices
        answers = {"STORED", "UNAVAILABLE"}  # an unasked outcome of a measurement is not the answer
        self.bench.send(self.id, "CalibrationRead")
        _, sig = self.bench.wait_for(
            self.id, lambda n, s: n == "CalibrationResult" and str(status.get(s["Status"])) in answers, timeout,
            "CalibrationRead")
        r = self._calibration(sig)
        if r.status != "STORED":
            raise CalibrationFailed(f"node {self.id} has no calibration of its own: {r.status} "
                                    f"({CALIBRATION_REASONS.get(r.status, 'see can/pour.dbc')})", r)
        return r

    # -- identification ------------------------------------------------------------------------------------
    def identify(self, path: str | Path, kind: str, seconds: float) -> tuple[int, str]:
        """Starts the controller's own experiment (ExperimentStart: identify or tilt, pour/experiment.h) and
        writes the bus as a candump -L log (atomically, the start frames included) until the node reports how
        it ended (Torque.Action outside RUN) and REST_S more (the held bucket at rest: the scale's noise), or
        seconds pass. Returns (frames, how it ended).
        A node in RUN gets a Stop just before the start: the two must land in one control tick, since the
        next sample starts a new run; a start refused as REFUSED_RUNNING is tried again, START_TRIES times
        in all. ParamRefused with the controller's reason; NodeTimeout if it never answers or never ends."""
        atomic.check_output_path(path, "log")
        kinds = {str(v): int(k) for k, v in self.bench.message("ExperimentStart").get_signal_by_name("Kind").choices.items()}
        cmd = self.bench.message("ExperimentStart").frame_id
        n, answered, ended, tail_end, tries = 0, False, None, None, 0
        m = self.bench.message("ExperimentStart")
        with atomic.atomic_path(path) as tmp:
            writer = can.CanutilsLogWriter(str(tmp), channel=self.bench.channel)

            def start() -> None:
                if self.state is not None and self.state.mode == "RUN":
                    self.bench.send(self.id, "Stop")
                self.bench.send(self.id, "ExperimentStart", Kind=kinds[kind])
                writer.on_message_received(can.Message(
                    timestamp=time.time(), arbitration_id=dbc.can_id(self.id, m.frame_id), is_extended_id=False,
                    data=m.encode({"Kind": kinds[kind]}, scaling=False, strict=True), channel=self.bench.channel))

            try:
                start()
                tries = 1
                for msg in self.bench.frames(seconds):
                    writer.on_message_received(msg)
                    n += 1
                    d = self.bench.decode(msg)
                    if d is None or d[0] != self.id:
                        continue
                    name, s = d[1], d[2]
                    if name == "ParamAck" and s["Request"] == cmd:
                        result = str(self.bench.message("ParamAck").get_signal_by_name("Result").choices[s["Result"]])
                        if result == "REFUSED_RUNNING" and tries < START_TRIES:
                            start()
                            tries += 1
                            continue
                        answered = True
                        if s["Result"] != 0:
                            reason = {"REFUSED_RUNNING": "the controller runs: stop it first",
                                      "REFUSED_ESTOP": "the e-stop is asserted",
                                      "REFUSED_FAULT": "the controller is in FAULT: clear it first"}.get(result, "")
                            raise ParamRefused(f"node {self.id} refused the {kind} experiment: {result} ({reason})",
                                               "ExperimentStart", result)
                    elif (name == "Torque" and answered and ended is None and s["Mode"] != 1
                          and s["Action"] >= EXPERIMENT_ENDED):
                        ended = EXPERIMENT_PHASES.get(s["Action"], str(s["Action"]))
                        tail_end = time.monotonic() + REST_S
                    if tail_end is not None and time.monotonic() >= tail_end:
                        break
            finally:
                writer.stop()
            last = self.state.describe() if self.state else f"node {self.id}: never heard on {self.bench.channel}"
            if not answered:
                raise NodeTimeout(f"node {self.id} did not answer the ExperimentStart within {seconds:g} s ({last}): "
                                  "no log written", self.state)
            if ended is None:
                raise NodeTimeout(f"node {self.id}'s {kind} experiment did not end within {seconds:g} s ({last}): no "
                                  "log written", self.state)
        return n, ended

    # -- telemetry -----------------------------------------------------------------------------------------
    def stream(self, seconds: float) -> Iterator[tuple[float, str, dict]]:
        """(time [s], message name, raw signals) of this node's frames for the given time."""
        for msg in self.bench.frames(seconds):
            d = self.bench.decode(msg)
            if d is not None and d[0] == self.id:
                yield msg.timestamp, d[1], d[2]

    def record(self, path: str | Path, seconds: float) -> int:
        """Writes every frame of the bus for the given time as a candump -L log (atomically); returns the count.
        NodeTimeout if this node sent nothing in that time (the log is then not written)."""
        atomic.check_output_path(path, "log")
        n = mine = 0
        with atomic.atomic_path(path) as tmp:
            writer = can.CanutilsLogWriter(str(tmp), channel=self.bench.channel)
            try:
                for msg in self.bench.frames(seconds):
                    writer.on_message_received(msg)
                    n += 1
                    mine += int(msg.arbitration_id >> dbc.NODE_SHIFT == self.id and not msg.is_extended_id)
            finally:
                writer.stop()
            if mine == 0:
                raise NodeTimeout(f"node {self.id} sent nothing on {self.bench.channel} in {seconds:g} s: no log "
                                  f"written", self.state)
        return n
