# SPDX-License-Identifier: MIT
"""can/pour.dbc (through cantools) and the firmware's C codec agree bit for bit: random and edge values,
packed by both; random bytes, unpacked by both; the C range checks are the DBC's [min|max]."""
from __future__ import annotations

import random
import re
import subprocess
import sys
from pathlib import Path

import cantools
import pytest

from conftest import BUILD_DIR, SOURCE_DIR
from pour import functions
from pour.can import dbc

SEED = 20261123
N_RANDOM = 400

# C message name -> (DBC message, C field order as DBC signal names). Heartbeat faults are a bit field in C
# and single-bit signals in the DBC: handled apart.
MESSAGES = {
    "sensors": ("Sensors", ["Seq", "Encoder", "ScaleRotating", "ScaleTarget"]),
    "torque": ("Torque", ["Seq", "Torque", "Action", "Mode", "Limits"]),
    "heartbeat": ("Heartbeat", ["Mode", "Faults", "RxDropped", "Overruns", "Counter", "Refused", "Held"]),
    "estop": ("Estop", ["Assert"]),
    "identity": ("Identity", ["WeightsHash", "TauMax", "FwVersion", "InitStatus"]),
    "clear_errors": ("ClearErrors", []),
    "stop": ("Stop", []),
    "reset": ("Reset", []),
    "calibration_start": ("CalibrationStart", []),
    "calibration_result": ("CalibrationResult", ["Status", "Stored", "EncoderReversed", "PolePairs", "Resistance",
                                                 "Inductance", "ElectricalOffset"]),
    "drive_telemetry": ("DriveTelemetry", ["Id", "Iq", "Vbus", "DriveFaults", "Crystal"]),
    "param_read": ("ParamRead", ["ParamId"]),
    "param_value": ("ParamValue", ["ParamId", "Value"]),
    "param_write": ("ParamWrite", ["ParamId", "Value"]),
    "param_ack": ("ParamAck", ["Request", "ParamId", "Result"]),
    "tare": ("Tare", ["Scales"]),
    "experiment_start": ("ExperimentStart", ["Kind"]),
    "param_save": ("ParamSave", []),
    "zero": ("Zero", []),
    "calibration_read": ("CalibrationRead", []),
}
SIGNAL_FREE = ("clear_errors", "stop", "reset", "calibration_start", "param_save", "zero", "calibration_read")
FAULT_BITS = {"Fault_StaleInput": 0x0001, "Fault_EStop": 0x0002, "Fault_BadInput": 0x0004,
              "Fault_Position": 0x0008, "Fault_Overspeed": 0x0010, "Fault_TorqueSign": 0x0020,
              "Fault_Encoder": 0x0040, "Fault_Volume": 0x0080, "Fault_CanWatchdog": 0x0100,
              "Fault_Seq": 0x0200, "Fault_Scale": 0x0400, "Fault_Drive": 0x0800}
# The drive's fault word (pour/drive_faults.h) in DriveTelemetry, the same way.
DRIVE_FAULT_BITS = {"DriveFault_Overcurrent": 0x0001, "DriveFault_HwOvercurrent": 0x0002,
                    "DriveFault_Overvoltage": 0x0004, "DriveFault_Undervoltage": 0x0008,
                    "DriveFault_Overtemp": 0x0010, "DriveFault_CurrentOffset": 0x0020, "DriveFault_Phase": 0x0040,
                    "DriveFault_EncoderDirection": 0x0080, "DriveFault_EncoderMismatch": 0x0100,
                    "DriveFault_Calibration": 0x0200, "DriveFault_I2t": 0x0400}
BIT_FIELDS = {"Faults": FAULT_BITS, "DriveFaults": DRIVE_FAULT_BITS}


@pytest.fixture(scope="module")
def db() -> cantools.database.can.Database:
    return cantools.database.load_file(str(SOURCE_DIR / "can" / "pour.dbc"))


class Harness:
    def __init__(self, exe: Path) -> None:
        if not exe.exists():
            raise FileNotFoundError(f"{exe} not built: build the host preset first")
        self.proc = subprocess.Popen([str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def ask(self, line: str) -> str:
        assert self.proc.stdin and self.proc.stdout
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        return self.proc.stdout.readline().strip()

    def close(self) -> None:
        assert self.proc.stdin
        self.proc.stdin.close()
        assert self.proc.wait(timeout=10) == 0


@pytest.fixture(scope="module")
def harness():
    h = Harness(BUILD_DIR / "bin" / "can_codec_harness")
    yield h
    h.close()


def raw_range(sig) -> tuple[int, int]:
    """The DBC's [min|max] in raw units."""
    lo = round((sig.minimum - sig.offset) / sig.scale)
    hi = round((sig.maximum - sig.offset) / sig.scale)
    return lo, hi


def field_ranges(db, cname: str) -> list[tuple[int, int]]:
    dbc_name, fields = MESSAGES[cname]
    msg = db.get_message_by_name(dbc_name)
    out = []
    for f in fields:
        if f in BIT_FIELDS:
            out.append((0, 0xFFFF))
        else:
            out.append(raw_range(msg.get_signal_by_name(f)))
    return out


def to_signals(cname: str, values: list[int]) -> dict[str, int]:
    _, fields = MESSAGES[cname]
    sigs: dict[str, int] = {}
    for f, v in zip(fields, values):
        if f in BIT_FIELDS:
            for name, bit in BIT_FIELDS[f].items():
                sigs[name] = 1 if v & bit else 0
        else:
            sigs[f] = v
    return sigs


def from_signals(cname: str, sigs: dict) -> list[int]:
    _, fields = MESSAGES[cname]
    out = []
    for f in fields:
        if f in BIT_FIELDS:
            out.append(sum(bit for name, bit in BIT_FIELDS[f].items() if sigs[name]))
        else:
            out.append(int(sigs[f]))
    return out


def c_pack(harness: Harness, cname: str, node: int, values: list[int]):
    ans = harness.ask(" ".join(["pack", cname, str(node)] + [str(v) for v in values])).split()
    if ans[0] == "einval":
        return None
    assert ans[0] == "ok", ans
    data = b"" if ans[3] == "-" else bytes.fromhex(ans[3])
    return int(ans[1]), int(ans[2]), data


def c_unpack(harness: Harness, cname: str, frame_id: int, data: bytes):
    hexdata = data.hex() if data else "-"
    ans = harness.ask(f"unpack {cname} {frame_id} {len(data)} {hexdata}").split()
    if ans[0] == "rx":
        return int(ans[1])
    assert ans[0] == "ok", ans
    return [int(x) for x in ans[1:]]


def edge_values(lo: int, hi: int) -> list[int]:
    return sorted({lo, lo + 1, -1 if lo < 0 else lo, 0 if lo <= 0 <= hi else lo, 1 if lo <= 1 <= hi else hi,
                   hi - 1, hi})


@pytest.mark.parametrize("cname", sorted(MESSAGES))
def test_pack_matches_dbc_for_random_and_edge_values(db, harness, cname):
    rng = random.Random(SEED)
    dbc_name, _ = MESSAGES[cname]
    msg = db.get_message_by_name(dbc_name)
    ranges = field_ranges(db, cname)
    cases = [[lo for lo, _ in ranges], [hi for _, hi in ranges]]
    for i, (lo, hi) in enumerate(ranges):
        for v in edge_values(lo, hi):
            case = [0 if a <= 0 <= b else a for a, b in ranges]
            case[i] = v
            cases.append(case)
    cases += [[rng.randint(lo, hi) for lo, hi in ranges] for _ in range(N_RANDOM)]
    for values in cases:
        node = rng.randint(0, dbc.NODE_ID_MAX)
        got = c_pack(harness, cname, node, values)
        assert got is not None, (cname, values)
        frame_id, dlc, data = got
        assert frame_id == dbc.can_id(node, msg.frame_id)
        assert dlc == msg.length
        want = msg.encode(to_signals(cname, values), scaling=False, strict=True)
        # The C codec only carries the fault bits the DBC names.
        assert data == want, (cname, values, data.hex(), want.hex())
        for i, f in enumerate(MESSAGES[cname][1]):
            if f in BIT_FIELDS:
                values[i] &= sum(BIT_FIELDS[f].values())
        assert from_signals(cname, msg.decode(data, scaling=False, decode_choices=False)) == values


@pytest.mark.parametrize("cname", sorted(n for n in MESSAGES if n not in SIGNAL_FREE))
def test_pack_refuses_what_the_dbc_calls_out_of_range(db, harness, cname):
    ranges = field_ranges(db, cname)
    dbc_name, fields = MESSAGES[cname]
    msg = db.get_message_by_name(dbc_name)
    refused = 0
    for i, (lo, hi) in enumerate(ranges):
        sig = None if fields[i] in BIT_FIELDS else msg.get_signal_by_name(fields[i])
        if sig is None:
            continue
        field_min = -(1 << (sig.length - 1)) if sig.is_signed else 0
        field_max = (1 << (sig.length - 1)) - 1 if sig.is_signed else (1 << sig.length) - 1
        for v in (lo - 1, hi + 1):
            if not field_min <= v <= field_max:
                continue  # not representable in the field: nothing to range-check
            case = [0 if a <= 0 <= b else a for a, b in ranges]
            case[i] = v
            assert c_pack(harness, cname, 0, case) is None, (cname, fields[i], v)
            with pytest.raises(cantools.database.errors.EncodeError):
                msg.encode(to_signals(cname, case), scaling=False, strict=True)
            refused += 1
    if cname in ("sensors", "torque", "heartbeat", "estop", "identity", "calibration_result", "drive_telemetry",
                 "param_ack", "tare", "experiment_start"):
        assert refused > 0


@pytest.mark.parametrize("cname", sorted(MESSAGES))
def test_unpack_matches_dbc_on_random_bytes(db, harness, cname):
    """Random payloads: the C codec accepts exactly those whose every signal is inside the DBC range, and
    then decodes the same raw values as cantools."""
    rng = random.Random(SEED + 1)
    dbc_name, fields = MESSAGES[cname]
    msg = db.get_message_by_name(dbc_name)
    accepted = rejected = 0
    ranges = {s.name: raw_range(s) for s in msg.signals}
    # Raw values a field can hold but its DBC range excludes (e.g. a scale's overload code -32768): random
    # bytes alone may hit them too rarely, so some payloads carry one on purpose.
    outside = [(s.name, v) for s in msg.signals for v in (ranges[s.name][0] - 1, ranges[s.name][1] + 1)
               if (-(1 << (s.length - 1)) if s.is_signed else 0) <= v
               <= ((1 << (s.length - 1)) - 1 if s.is_signed else (1 << s.length) - 1)]
    for i in range(N_RANDOM):
        if i % 4 == 1 and outside:
            name, v = rng.choice(outside)
            sigs = {n: rng.randint(lo, hi) for n, (lo, hi) in ranges.items()}
            sigs[name] = v
            data = msg.encode(sigs, scaling=False, strict=False)
        elif i % 2:
            data = bytes(rng.getrandbits(8) for _ in range(msg.length))
        else:  # in range by construction, so that both answers are exercised for every message
            data = msg.encode({n: rng.randint(lo, hi) for n, (lo, hi) in ranges.items()}, scaling=False)
        sigs = msg.decode(data, scaling=False, decode_choices=False)
        in_range = all(ranges[n][0] <= sigs[n] <= ranges[n][1] for n in ranges)
        got = c_unpack(harness, cname, msg.frame_id, data)
        if in_range:
            assert got == from_signals(cname, sigs), (cname, data.hex())
            accepted += 1
        else:
            assert got == -3, (cname, data.hex(), sigs)  # POUR_CAN_RX_OUT_OF_RANGE
            rejected += 1
    assert accepted >= N_RANDOM // 2
    if outside:
        assert rejected > 0


@pytest.mark.parametrize("cname", sorted(MESSAGES))
def test_unpack_rejects_every_wrong_dlc(db, harness, cname):
    dbc_name, _ = MESSAGES[cname]
    msg = db.get_message_by_name(dbc_name)
    for dlc in range(9):
        if dlc == msg.length:
            continue
        assert c_unpack(harness, cname, msg.frame_id, bytes(dlc)) == -2, (cname, dlc)  # BAD_DLC


def test_cmd_ids_and_lengths_match_the_c_header(db, source_dir):
    header = (source_dir / "firmware" / "can" / "include" / "pour" / "can_codec.h").read_text()
    names = {"Heartbeat": "HEARTBEAT", "Estop": "ESTOP", "Sensors": "SENSORS",
             "Torque": "TORQUE", "ClearErrors": "CLEAR_ERRORS", "Stop": "STOP", "Reset": "RESET",
             "Identity": "IDENTITY", "CalibrationStart": "CALIBRATION_START",
             "CalibrationResult": "CALIBRATION_RESULT", "DriveTelemetry": "DRIVE_TELEMETRY",
             "ParamRead": "PARAM_READ", "ParamValue": "PARAM_VALUE",
             "ParamWrite": "PARAM_WRITE", "ParamSave": "PARAM_SAVE", "ParamAck": "PARAM_ACK", "Tare": "TARE", "ExperimentStart": "EXPERIMENT_START",
             "Zero": "ZERO", "CalibrationRead": "CALIBRATION_READ"}
    assert sorted(m.name for m in db.messages) == sorted(names)
    for m in db.messages:
        c = names[m.name]
        assert f"#define POUR_CAN_CMD_{c} 0x{m.frame_id:02X}u" in header
        assert f"#define POUR_CAN_DLC_{c} {m.length}u" in header
        assert m.frame_id <= dbc.CMD_MASK


def test_every_signal_has_a_unit_or_choices_and_a_comment(db):
    for m in db.messages:
        assert m.comment, m.name
        for s in m.signals:
            assert s.comment, (m.name, s.name)
            assert s.unit or s.choices or s.length == 1 or s.name in ("Seq", "Counter", "Action",
                                                                        "Limits", "WeightsHash", "FwVersion",
                                                                        "InitStatus", "PolePairs", "Value", "Scales"),\
                (m.name, s.name)


def test_cantools_decode_of_candump_log_shows_units(db, harness, source_dir):
    """What a bench engineer runs: candump -L lines piped through cantools decode."""
    lines = []
    frames = [("sensors", [7, 131071, -5, 12345]),
              ("torque", [7, -16384, 2, 1, 2]), ("heartbeat", [1, 0x0121, 3, 4, 5, 2, 1]), ("estop", [1]),
              ("identity", [0x1234ABCD, 2000, 2, 0]), ("clear_errors", []), ("stop", []), ("reset", []),
              ("calibration_start", []), ("calibration_result", [7, 2, 0, 0, 0, 0, 0]),
              ("calibration_read", []), ("calibration_result", [19, 0, 1, 4, 450, 220, 12]),
              ("drive_telemetry", [-1500, 2500, 24100, 0x0102, 6])]
    for cname, values in frames:
        frame_id, _, data = c_pack(harness, cname, 0, values)
        lines.append(f"(1700000000.{len(lines):06d}) vcan0 {frame_id:03X}#{data.hex().upper()}")
    out = subprocess.run([sys.executable, "-m", "cantools", "decode", str(source_dir / "can" / "pour.dbc")],
                         input="\n".join(lines) + "\n", capture_output=True, text=True, timeout=60, check=True)
    text = out.stdout
    assert "Encoder: 131071 counts" in text
    assert "ScaleRotating: -5 g" in text and "ScaleTarget: 12345 g" in text
    assert "Torque: -50.0 %" in text
    assert "Mode: RUN" in text
    assert "Fault_CanWatchdog: 1" in text
    assert "Fault_TorqueSign: 1" in text
    assert "TauMax: 20.0 N.m" in text
    assert "Assert: ASSERT" in text
    assert "Status: REFUSED_ESTOP" in text and "Stored: CORRUPT" in text  # a refusal's reason, by name
    assert "CalibrationRead(" in text
    assert "Status: STORED" in text and "Stored: OK" in text and "Resistance: 0.45 Ohm" in text  # the read's answer
    assert "Iq: 5.0 A" in text and "Vbus: 24.1 V" in text and "Crystal: 24 MHz" in text
    assert "DriveFault_HwOvercurrent: 1" in text and "DriveFault_EncoderMismatch: 1" in text
    assert "ClearErrors(" in text
    assert "Stop(" in text and "Reset(" in text


def test_calibration_status_names_are_the_codec_s(db):
    """CalibrationResult.Status's choices are the codec's POUR_CAN_CAL_* values, name for name."""
    header = (Path(SOURCE_DIR) / "firmware/can/include/pour/can_codec.h").read_text()
    ours = {int(v): k for k, v in re.findall(r"#define POUR_CAN_CAL_(\w+) (\d+)u", header)
            if not k.endswith("_MAX")}
    choices = db.get_message_by_name("CalibrationResult").get_signal_by_name("Status").choices
    assert {int(k): str(v) for k, v in choices.items()} == ours
    assert len(ours) == 20 and "MEASURING" in ours.values() and "REFUSED_NO_SENSORS" in ours.values()
    assert ours[19] == "STORED"


def test_param_ids_in_the_dbc_are_the_firmware_table(db, harness):
    """ParamId's value table in every parameter message names the ids of firmware/include/pour/params.h, the
    one declaration; ParamAck's results are pour_param_result_t's, then an ExperimentStart's refusals."""
    table = {}
    for i in range(256):
        ans = harness.ask(f"param {i}").split()
        if ans[0] == "ok":
            table[i] = ans[1]
    assert len(table) >= 20 and sorted(table) == list(range(len(table)))
    for name in ("ParamRead", "ParamValue", "ParamWrite", "ParamAck"):
        choices = db.get_message_by_name(name).get_signal_by_name("ParamId").choices
        assert {int(k): str(v) for k, v in choices.items()} == table, name
    results = db.get_message_by_name("ParamAck").get_signal_by_name("Result").choices
    assert [str(results[k]) for k in sorted(results)] == ["OK", "UNKNOWN_ID", "OUT_OF_RANGE", "BUSY",
                                                          "INCONSISTENT", "NO_STORAGE", "NO_SAMPLE",
                                                          "REFUSED_RUNNING", "REFUSED_ESTOP", "REFUSED_FAULT"]
    # The ExperimentStart's refusals, beyond pour_param_result_t, are can_codec.h's.
    header = (SOURCE_DIR / "firmware" / "can" / "include" / "pour" / "can_codec.h").read_text()
    for k in (7, 8, 9):
        assert f"#define POUR_CAN_ACK_{results[k]} {k}u" in header


def test_dbc_for_node_shifts_every_id(db):
    for node in (0, 1, 37, 63):
        other = cantools.database.load_string(dbc.dbc_for_node(node), "dbc")
        assert sorted(m.frame_id for m in other.messages) == sorted((node << 5) | m.frame_id for m in db.messages)
        for m in db.messages:
            o = other.get_message_by_name(m.name)
            assert [s.name for s in o.signals] == [s.name for s in m.signals]
            assert o.comment == m.comment.replace("node id 0.", f"node id {node}.")
            assert all(so.comment == s.comment for so, s in zip(o.signals, m.signals))
        assert other.get_message_by_name("Heartbeat").get_signal_by_name("Mode").choices[1] == "RUN"


@pytest.mark.parametrize("bad", ["64", "-1", "x", "1.5"])
def test_dbc_generator_rejects_bad_node_ids(bad, tmp_path):
    out = subprocess.run([sys.executable, "-m", "pour.can.dbc", "--node", bad, "-o", str(tmp_path / "x.dbc")],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert "pour-can-dbc: error:" in out.stderr
    assert not (tmp_path / "x.dbc").exists()


def test_dbc_generator_writes_a_loadable_file(tmp_path):
    out = subprocess.run([sys.executable, "-m", "pour.can.dbc", "--node", "0x3", "-o", str(tmp_path / "n3.dbc")],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    db3 = cantools.database.load_file(str(tmp_path / "n3.dbc"))
    assert db3.get_message_by_name("Torque").frame_id == 0x72


def test_harness_answers_bad_requests_without_dying(harness):
    assert harness.ask("pack sensors 0 1").startswith("error")
    assert harness.ask("unpack torque 4096 7 00").startswith("error")
    assert harness.ask("frobnicate x").startswith("error")
    assert harness.ask("pack sensors 64 0 0 0 0") == "einval"


def test_the_heartbeat_carries_one_signal_per_fault_the_core_names(db):
    """Each of the core's fault bits (its name table, pour_fault_name) has its Fault_ signal at bit 8 + i."""
    hb = db.get_message_by_name("Heartbeat")
    signals = {s.name: 1 << (s.start - 8) for s in hb.signals if s.name.startswith("Fault_")}
    assert signals == FAULT_BITS
    assert sorted(signals.values()) == [1 << i for i in range(16) if functions.fault_name(1 << i) is not None]


def test_the_dbc_protocol_is_the_firmware_version():
    """Identity's FwVersion is the DBC's protocol number, so a tool can tell that it holds the node's DBC."""
    control_h = (SOURCE_DIR / "firmware/include/pour/control.h").read_text()
    fw = int(re.search(r"#define POUR_FIRMWARE_VERSION (\d+)u", control_h).group(1))
    assert dbc.protocol_version(cantools.database.load_file(str(dbc.default_dbc())).version) == fw


@pytest.mark.parametrize("version", [None, "", "pour CAN protocol", "pour CAN protocol 6b", "other 6"])
def test_a_dbc_version_that_names_no_protocol_is_refused(version):
    with pytest.raises(ValueError, match="is not 'pour CAN protocol N'"):
        dbc.protocol_version(version)
