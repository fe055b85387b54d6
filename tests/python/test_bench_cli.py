# SPDX-License-Identifier: MIT
"""pour-bench's bad input on any kernel (the bus itself is tested in the user-mode Linux guest,
tests/can/guest/test_bench.py): a bad command line is 2, a bus that cannot open is 1, each with a message that
names the problem."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest


def bench(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pour.bench.cli", *argv], capture_output=True, text=True,
                          timeout=60)


@pytest.mark.parametrize("argv, needle", [
    (["--node", "64", "info"], "node id 64 outside 0..63"),
    (["--node", "x", "info"], "'x' is not a decimal integer"),
    (["--timeout", "0", "info"], "not a number of seconds"),
    (["--expect-hash", "0xnothex", "clear"], "not a 32-bit policy hash"),
    (["config", "set", "--raw", "omega_max", "1.5"], "VALUE: '1.5' is not a decimal integer"),
    (["config", "set", "omega_max", "fast"], "VALUE: 'fast' is not a number (in rad/s"),
    (["config", "set", "omega_max", "1000"], "omega_max = 1000 rad/s is outside 1e-06 .. 2 rad/s"),
    (["config", "set", "encoder_bits", "30"], "encoder_bits = 30 bits is outside"),
    (["config", "set", "nosuch", "1"], "no parameter 'nosuch'"),
    (["config", "restore", "nosuch.json"], "nosuch.json: cannot read (No such file or directory)"),
    (["config", "set", "omega_max"], "the following arguments are required: value"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
    ([], "the following arguments are required: COMMAND"),
])
def test_bad_command_lines_are_status_2(argv, needle):
    r = bench(*argv)
    assert r.returncode == 2 and needle in r.stderr, r.stderr


def test_a_bad_weights_file_is_status_2(tmp_path):
    bad = tmp_path / "weights.h"
    bad.write_text("not a header\n")
    r = bench("--channel", "nosuchcan0", "--weights", str(bad), "clear")
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith(f"pour-bench: error: --weights {bad}: "), r.stderr
    r = bench("--channel", "nosuchcan0", "reset")
    assert r.returncode == 2 and "'reset' can move the axis: give the policy you expect" in r.stderr, r.stderr


def test_calibrate_moves_the_axis_so_it_needs_the_expected_policy():
    r = bench("--channel", "nosuchcan0", "calibrate")
    assert r.returncode == 2 and "'calibrate' can move the axis: give the policy you expect" in r.stderr, r.stderr
    r = bench("--channel", "nosuchcan0", "--expect-hash", "1", "calibrate", "--seconds", "0")
    assert r.returncode == 2 and "not a number of seconds" in r.stderr, r.stderr


def test_a_bus_that_cannot_open_says_which():
    r = bench("--channel", "nosuchcan0", "scan")
    assert r.returncode == 1
    assert "pour-bench: error: cannot open CAN bus socketcan:nosuchcan0" in r.stderr, r.stderr


def test_config_list_names_the_dbc_parameters_without_a_bus():
    r = bench("--channel", "nosuchcan0", "config", "list")
    assert r.returncode == 0, r.stderr
    assert "  4 omega_max" in r.stdout and " 22 scale_target_tare" in r.stdout, r.stdout
    # each with its range and its compiled default, in SI units (the firmware's table through libpoursim)
    assert "  4 omega_max  [1e-06 .. 2 rad/s; default 2 rad/s]" in r.stdout.splitlines(), r.stdout


def candump_log(path, node: int = 0, samples: int = 300, drive: bool = False) -> None:
    """A candump -L log of one pour's frames for node, packed by the DBC: the encoder turning 1 count per
    sample, torque at 25 % of a 20 N·m tau_max, a heartbeat and identity every 100 samples (RUN, then
    FAULT with StaleInput), and with drive a DriveTelemetry beside each heartbeat."""
    import cantools

    from pour.can import dbc
    db = cantools.database.load_file(str(dbc.default_dbc()))
    lines = []

    def frame(t: float, name: str, **sig) -> None:
        m = db.get_message_by_name(name)
        data = m.encode(sig, scaling=False)
        lines.append(f"({1700000000 + t:.6f}) vcan0 {dbc.can_id(node, m.frame_id):03X}#{data.hex().upper()}")

    faults = {f"Fault_{n}": 0 for n in ("StaleInput", "EStop", "BadInput", "Position", "Overspeed", "TorqueSign",
                                         "Encoder", "Volume", "CanWatchdog", "Seq", "Scale", "Drive")}
    for k in range(samples):
        t = k * 0.001
        frame(t, "Sensors", Seq=k % 256, Encoder=k, ScaleRotating=10000 - k, ScaleTarget=k)
        frame(t, "Torque", Seq=k, Torque=8192, Action=3, Mode=1, Limits=0)
        if k % 100 == 0:
            late = k >= 200
            frame(t, "Heartbeat", Mode=2 if late else 1, **{**faults, "Fault_StaleInput": int(late)}, RxDropped=0,
                  Overruns=0, Counter=k // 100, Refused=0, Held=0)
            frame(t, "Identity", WeightsHash=0x1234, TauMax=2000, FwVersion=3, InitStatus=0)
            if drive:  # Iq 2 A, bus 24 V; the drive's overcurrent latched with the late heartbeat
                frame(t, "DriveTelemetry", Id=0, Iq=1000, Vbus=24000, Crystal=6, **{
                    s.name: int(late and s.name == "DriveFault_Overcurrent")
                    for s in db.get_message_by_name("DriveTelemetry").signals if s.name.startswith("DriveFault_")})
    path.write_text("\n".join(lines) + "\n")


def test_plot_of_a_log_draws_the_node_and_saves_a_png(tmp_path):
    log = tmp_path / "run.log"
    candump_log(log)
    png = tmp_path / "plot.png"
    r = bench("plot", "--replay", str(log), "--fast", "--no-window", "--png", str(png))
    assert r.returncode == 0, r.stderr
    assert "pour-bench plot: 606 frames of node 0" in r.stdout, r.stdout  # 300 samples, 300 torques, 3 + 3
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_of_a_log_with_drive_telemetry_draws_iq_the_bus_and_the_drives_faults(tmp_path, monkeypatch):
    from pour.bench import node as bn
    from pour.bench import plot
    log = tmp_path / "run.log"
    candump_log(log, drive=True)
    drawn = {}
    update = plot.Figure.update

    def keep(self, s):
        update(self, s)
        drawn.update(iq=list(self.l_iq.get_ydata()), vbus=list(self.l_vbus.get_ydata()),
                     faults=self.fault_text.get_text(), note=self.drive_text.get_text())

    monkeypatch.setattr(plot.Figure, "update", keep)
    used = plot.run(plot.replay(log, paced=False), bn.load_dbc(), 0, 60.0, 17, 100.0, tmp_path / "p.png", False)
    assert used == 609  # 300 samples, 300 torques, 3 heartbeats, 3 identities, 3 drive telemetries
    assert drawn["iq"] == [2.0, 2.0, 2.0] and drawn["vbus"] == [24.0, 24.0, 24.0] and drawn["note"] == ""
    assert "drive Overcurrent 0.2-0.2 s" in drawn["faults"] and "StaleInput 0.2-0.2 s" in drawn["faults"]
    candump_log(log)
    plot.run(plot.replay(log, paced=False), bn.load_dbc(), 0, 60.0, 17, 100.0, tmp_path / "p.png", False)
    assert drawn["iq"] == [] and drawn["note"].startswith("no DriveTelemetry from this node")


def test_plot_series_theta_rate_torque_and_faults():
    from pour.bench import plot
    s = plot.Series(window_s=100.0, encoder_bits=17)
    names = ["Fault_StaleInput", "Fault_EStop"]
    s.add("Identity", {"TauMax": 2000}, names)
    for k in range(300):  # 300 samples: Seq wraps at 256, the encoder below upright (counts wrap under 2^17)
        s.add("Sensors", {"Seq": k % 256, "Encoder": (131072 - 10 * k) % 131072, "ScaleRotating": 500,
                          "ScaleTarget": -20}, names)
        s.add("Torque", {"Torque": -16384}, names)
    s.add("Heartbeat", {"Mode": 2, "Fault_StaleInput": 1, "Fault_EStop": 0}, names)
    assert s.theta[-1][0] == 0.299  # the samples' clock across the wrap
    assert abs(s.theta[-1][1] - (-2990 * 360 / 131072)) < 1e-9
    assert abs(s.omega[-1][1] - (-10 * 360 / 131072 * 1000)) < 1e-6  # deg/s at 10 counts per ms
    assert s.torque[-1][1] == -10.0  # half of tau_max, backwards
    assert s.scales[-1][1:] == (0.5, -0.02)
    assert s.faults[-1] == (0.299, ["StaleInput"]) and s.modes[-1] == (0.299, 2)


@pytest.mark.parametrize("make, argv, status, needle", [
    (None, ["--replay", "nosuch.log", "--no-window", "--png", "x.png"], 2, "nosuch.log: no such file"),
    ("garbage", ["--no-window", "--png", "x.png"], 1, "not a candump -L log"),
    ("node5", ["--no-window", "--png", "x.png"], 1, "no frame of node 0 to plot"),
    ("log", ["--no-window"], 2, "--no-window draws nothing to see: give --png FILE"),
    ("log", ["--no-window", "--png", "nosuchdir/x.png"], 2, "does not exist"),
    ("log", ["--encoder-bits", "30", "--no-window", "--png", "x.png"], 2, "--encoder-bits 30 outside 8..24"),
])
def test_plot_bad_input(tmp_path, make, argv, status, needle):
    log = tmp_path / "run.log"
    if make == "garbage":
        log.write_text("this is not a log\n")
    elif make == "node5":
        candump_log(log, node=5)
    elif make == "log":
        candump_log(log)
    argv = [str(tmp_path / a) if a.endswith((".log", ".png")) else a for a in argv]
    r = bench("plot", *(["--replay", str(log)] if make else []), "--fast", *argv)
    assert r.returncode == status, (r.stdout, r.stderr)
    assert needle in r.stderr, r.stderr


@pytest.mark.parametrize("fw, refused", [(None, False), (-1, True)])
def test_a_node_of_another_protocol_is_refused_before_motion(fw, refused):
    """check_protocol (which every motion command runs first) against a node on a python-can virtual bus
    whose Identity reports this DBC's protocol (None) or the one before it (-1)."""
    import can

    from pour.bench import node as bn
    channel = f"proto{fw}"
    with bn.Bench(bus=can.Bus(interface="virtual", channel=channel)) as b, \
            can.Bus(interface="virtual", channel=channel) as peer:
        version = b.protocol + (fw or 0)
        for name, sig in (("Identity", dict(WeightsHash=0x1234, TauMax=2000, FwVersion=version, InitStatus=0)),
                          ("Heartbeat", dict(Mode=0, Faults=0, RxDropped=0, Overruns=0, Counter=1, Refused=0))):
            m = b.db.get_message_by_name(name)
            sig = {s.name: sig.get(s.name, 0) for s in m.signals}
            peer.send(can.Message(arbitration_id=m.frame_id, data=m.encode(sig, scaling=False), is_extended_id=False))
        n = b.node(0)
        if refused:
            with pytest.raises(bn.BenchError, match=f"node 0 runs firmware {version}, but this DBC is protocol "
                                                    f"{b.protocol}"):
                n.check_protocol(timeout=1.0)
        else:
            assert n.check_protocol(timeout=1.0).identity.fw_version == b.protocol


class _FakeNode:
    """A controller of this DBC's protocol on a python-can virtual bus, for the read-only calibration query:
    its heartbeat and identity every 20 ms, and the given CalibrationResult (signal names and value names as
    the DBC gives them) to each CalibrationRead, after an unasked outcome of a measurement that is not the
    answer. Every frame it receives is kept."""

    def __init__(self, channel: str, answer: dict, drive: dict | None = None, mode: str = "RUN",
                 faults: dict | None = None) -> None:
        import threading

        import can

        from pour.bench import node as bn
        self.db = bn.load_dbc()
        self.bus = can.Bus(interface="virtual", channel=channel)
        self.answer = answer
        self.drive, self.mode, self.faults = drive, mode, faults or {}
        self.params: dict[int, int] = {}  # a parameter store answering ParamRead and ParamWrite
        self.writes: list[tuple[int, int]] = []
        self.received: list[str] = []
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True)

    def send(self, name: str, **named) -> None:
        import can
        m = self.db.get_message_by_name(name)
        raw = {}
        for s in m.signals:
            v = named.get(s.name, 0)
            raw[s.name] = ({str(n): k for k, n in s.choices.items()}[v] if isinstance(v, str)
                           else round(v / s.scale))
        self.bus.send(can.Message(arbitration_id=m.frame_id, data=m.encode(raw, scaling=False),
                                  is_extended_id=False))

    def run(self) -> None:
        from pour.can import dbc
        counter = 0
        while not self.stop.is_set():
            self.send("Identity", WeightsHash=0x1234, TauMax=20.0, FwVersion=dbc.protocol_version(self.db.version))
            self.send("Heartbeat", Mode=self.mode, Counter=counter % 256, **self.faults)
            if self.drive is not None:  # with every heartbeat, as a controller with a drive of its own sends it
                self.send("DriveTelemetry", **self.drive)
            counter += 1
            msg = self.bus.recv(0.02)
            if msg is None:
                continue
            name = self.db.get_message_by_frame_id(msg.arbitration_id).name
            self.received.append(name)
            if name in ("ParamRead", "ParamWrite"):
                self.param(name, self.db.decode_message(msg.arbitration_id, msg.data, scaling=False,
                                                        decode_choices=False))
            if name == "CalibrationRead":
                self.send("CalibrationResult", Status="NO_ENCODER", Stored="EMPTY")
                self.send("CalibrationResult", **self.answer)

    def param(self, name: str, sig: dict) -> None:
        """The controller's answers: the value (ParamValue), or a ParamAck refusing a set whose theta_min is
        not below its theta_max (INCONSISTENT), as pour_params_check judges it."""
        pid = sig["ParamId"]
        if name == "ParamWrite":
            trial = {**self.params, pid: sig["Value"]}
            if trial.get(2, -1) >= trial.get(3, 1):
                self.send("ParamAck", Request="ParamWrite", ParamId=pid, Result="INCONSISTENT")
                return
            self.params = trial
            self.writes.append((pid, sig["Value"]))
        self.send("ParamValue", ParamId=pid, Value=self.params.get(pid, 0))

    def __enter__(self) -> "_FakeNode":
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop.set()
        self.thread.join(5)
        self.bus.shutdown()


@pytest.mark.parametrize("answer, status, needle", [
    (dict(Status="STORED", Stored="OK", EncoderReversed=1, PolePairs=8, Resistance=0.304, Inductance=0.231,
          ElectricalOffset=28.125),
     0, "node 0: resistance 0.304 Ohm, inductance 0.231 mH, pole pairs 8, encoder direction reversed, "
        "electrical offset 28.1 deg (stored OK)"),
    (dict(Status="STORED", Stored="CORRUPT"), 0, "node 0: stored calibration: CORRUPT"),
    (dict(Status="UNAVAILABLE", Stored="EMPTY"), 1, "pour-bench: error: node 0 has no calibration of its own: "
                                                    "UNAVAILABLE (this controller has no drive of its own"),
])
def test_calibration_reads_the_stored_block_without_asking_or_moving(answer, status, needle, capsys, monkeypatch):
    """pour-bench calibration against a node on a python-can virtual bus: no --expect-hash, no confirmation
    (stdin is never read), one CalibrationRead and nothing else on the bus, and the answer by name."""
    from pour.bench import cli as bench_cli
    monkeypatch.setattr("sys.stdin", None)
    channel = f"calread{status}{answer['Stored']}"
    with _FakeNode(channel, answer) as node:
        rc = bench_cli.main(["--interface", "virtual", "--channel", channel, "calibration"])
    out = capsys.readouterr()
    assert rc == status, out
    assert needle in (out.out if status == 0 else out.err), out
    assert node.received == ["CalibrationRead"]


@pytest.mark.parametrize("drive, needle", [
    (dict(Id=0.25, Iq=-3.5, Vbus=23.875, DriveFault_Overcurrent=1, DriveFault_I2t=1),
     "node 0: drive faults Overcurrent, I2t, Iq -3.500 A, Id 0.250 A, bus 23.88 V"),
    (dict(Id=0.0, Iq=1.25, Vbus=24.0), "node 0: drive faults none, Iq 1.250 A, Id 0.000 A, bus 24.00 V"),
    (None, "node 0: no DriveTelemetry (a controller without a drive of its own)"),
])
def test_faults_names_the_drives_faults_from_its_telemetry(drive, needle, capsys):
    """pour-bench faults against a node on a python-can virtual bus that sends DriveTelemetry (scaled by the
    DBC: Iq 0.002 A, Vbus 0.001 V a count) with each heartbeat, or none."""
    from pour.bench import cli as bench_cli
    channel = f"drivefaults{len(needle)}"
    with _FakeNode(channel, {}, drive=drive, mode="FAULT", faults=dict(Fault_Drive=1)):
        rc = bench_cli.main(["--interface", "virtual", "--channel", channel, "faults"])
    out = capsys.readouterr()
    assert rc == 0, out
    lines = out.out.splitlines()
    assert lines[0].startswith("node 0: mode FAULT, faults Drive,") and lines[1] == needle, out.out


@pytest.mark.parametrize("held", [1, 0])
def test_faults_says_a_held_node_waits_for_a_reset(held, capsys):
    """Heartbeat's Held (protocol 8: the board boots held, a Stop holds): pour-bench says RUN waits for a Reset."""
    from pour.bench import cli as bench_cli
    channel = f"heldnode{held}"
    with _FakeNode(channel, {}, mode="IDLE", faults=dict(Held=held)):
        rc = bench_cli.main(["--interface", "virtual", "--channel", channel, "faults"])
    out = capsys.readouterr()
    assert rc == 0, out
    first = out.out.splitlines()[0]
    assert first.startswith("node 0: mode IDLE, faults none,"), out.out
    assert first.endswith(", held (RUN waits for a Reset: pour-bench reset)") == bool(held), out.out


def test_without_socketcan_the_error_points_to_the_no_can_hardware_doc(monkeypatch, capsys):
    """A kernel without SocketCAN (Errno 97, EAFNOSUPPORT, as in a container): one line that says so and names
    the doc section, which exists."""
    import errno

    import can

    from pour.bench import cli as bench_cli
    from conftest import SOURCE_DIR

    def no_socketcan(*args, **kwargs):
        raise OSError(errno.EAFNOSUPPORT, "Address family not supported by protocol")

    monkeypatch.setattr(can, "Bus", no_socketcan)
    assert bench_cli.main(["--channel", "vcan0", "scan"]) == 1
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("pour-bench: error: cannot open CAN bus socketcan:vcan0: [Errno 97]"), line
    assert "this kernel has no SocketCAN" in line and 'docs/bench.md, "No CAN hardware"' in line, line
    doc = (SOURCE_DIR / "docs" / "bench.md").read_text()
    assert "\n## No CAN hardware\n" in doc and "ip link add dev vcan0 type vcan" in doc


def test_every_subcommand_and_option_has_help():
    import argparse

    from pour.bench import cli as bench_cli

    def walk(parser, path):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                helped = {a.dest for a in action._choices_actions if a.help}
                for name, sub in action.choices.items():
                    assert name in helped, f"{path} {name}: no help"
                    yield from walk(sub, f"{path} {name}")
            elif not isinstance(action, (argparse._HelpAction, argparse._VersionAction)):
                yield path, action

    actions = list(walk(bench_cli.parser(), "pour-bench"))
    assert len(actions) > 20
    missing = [f"{path} {a.option_strings or a.dest}" for path, a in actions if not a.help]
    assert not missing, missing


def test_bus_options_are_named_as_python_can_names_them():
    from pour.bench import cli as bench_cli
    opts = {o for a in bench_cli.parser()._actions for o in a.option_strings}
    assert {"--channel", "--interface", "--node"} <= opts and "--iface" not in opts


def test_config_get_set_dump_and_restore_in_si_units(tmp_path, capsys):
    """Against a node on a python-can virtual bus that stores what it is written: get and set read and take SI
    units (the firmware table's urad/s as rad/s); a dump holds every parameter; a restore writes them all
    back, a write the node refuses as inconsistent (theta_min above the theta_max then in force) after the
    others."""
    from pour.bench import cli as bench_cli
    from pour.bench import params as bp
    channel = "params-si"
    with _FakeNode(channel, {}, mode="IDLE") as node:
        node.params.update({prm.id: prm.min for prm in bp.table().values()})  # every value in range
        node.params.update({2: -50000, 3: 2356194, 4: 1500000, 14: 4000})
        base = ["--interface", "virtual", "--channel", channel]
        assert bench_cli.main(base + ["config", "get", "omega_max", "stop_timeout"]) == 0
        out = capsys.readouterr().out.splitlines()
        assert out == ["omega_max 1.5 rad/s (range 1e-06 .. 2 rad/s; default 2 rad/s; raw 1500000 urad/s)",
                       "stop_timeout 4 s (range 0.001 .. 65.535 s; default 5 s; raw 4000 ms)"], out
        assert bench_cli.main(base + ["config", "get", "--raw", "omega_max"]) == 0
        assert capsys.readouterr().out == "omega_max 1500000\n"
        assert bench_cli.main(base + ["config", "set", "omega_max", "1.75"]) == 0
        assert capsys.readouterr().out.startswith("omega_max 1.75 rad/s (")
        assert node.params[4] == 1750000
        dump = tmp_path / "node0.json"
        assert bench_cli.main(base + ["config", "dump", str(dump)]) == 0
        count = len(bp.table())  # every row of the firmware's table
        assert f"{dump}: {count} parameters of node 0" in capsys.readouterr().out
        saved = bp.load_dump(dump, bp.table())
        assert saved["omega_max"] == 1750000 and saved["theta_max"] == 2356194 and len(saved) == count
        # Another set in force: theta_max below the dump's theta_min, so writing theta_min first is refused.
        node.params.update({2: -80000, 3: 50000, 4: 1000})
        doc = json.loads(dump.read_text())
        doc["params"]["theta_min"]["raw"] = 100000
        dump.write_text(json.dumps(doc))
        node.writes.clear()
        assert bench_cli.main(base + ["config", "restore", str(dump)]) == 0
        assert f"{count} parameters restored" in capsys.readouterr().out
        assert node.params[2] == 100000 and node.params[3] == 2356194 and node.params[4] == 1750000
        assert [pid for pid, _ in node.writes].index(2) > [pid for pid, _ in node.writes].index(3)


@pytest.mark.parametrize("text, why", [
    ("{", "not a config dump"),
    ('{"format": "other"}', "not a config dump"),
    ('{"format": "pour-bench config dump 1", "params": {"omega_mx": {"raw": 1}}}', "no parameter 'omega_mx'"),
    ('{"format": "pour-bench config dump 1", "params": {"omega_max": {"raw": 1.5}}}', "no integer \"raw\""),
    ('{"format": "pour-bench config dump 1", "params": {"encoder_bits": {"raw": 30}}}', "encoder_bits = 30 bits is outside"),
    ('{"format": "pour-bench config dump 1", "params": {"omega_max": {"raw": 5, "unit": "mrad/s"}}}', "is in 'mrad/s'"),
])
def test_a_dump_it_cannot_use_is_refused_before_the_bus_opens(tmp_path, text, why):
    dump = tmp_path / "d.json"
    dump.write_text(text)
    r = bench("--channel", "nosuchcan0", "config", "restore", str(dump))
    assert r.returncode == 2 and why in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr
