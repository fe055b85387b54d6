# SPDX-License-Identifier: MIT
"""pour-bench: bring a pour controller up on a CAN bus (scan, info, faults, e-stop, parameters, logs).

Commands that can make the axis move (clear, which resumes a run, reset, identify, the controller's own
identification experiment, and calibrate, the drive's) say so, check the node's policy hash against
--expect-hash or --weights first, and ask for confirmation unless --yes.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pour import atomic, cli
from pour.bench import node as bn
from pour.bench import params as bp
from pour.libpoursim import SimError
from pour.policy import weights_h

PROG = "pour-bench"
EPILOG = ("Exit status (the same meanings in every pour program): 0 done; 1 a failure while running (no node, two "
          "nodes on one id, a node that does not answer, a request the controller refuses, a policy that is not "
          "the expected one); 2 bad input (the command line, or the weights.h it names). Numbers are decimal; a "
          "hash may be 0x hex.")


# Commands that can move the axis, and how.
MOTION = {"clear": "a run resumes", "reset": "a new run starts once samples flow",
          "identify": "the identification experiment moves the bucket",
          "calibrate": "the drive's calibration releases the brake and turns the motor (up to 10 deg of output)"}


class UsageError(Exception):
    """Bad input: exit status 2."""


def _int(text: str) -> int:
    try:
        return int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a decimal integer") from None


def _hash(text: str) -> int:
    try:
        v = int(text[2:], 16) if text.lower().startswith("0x") else int(text, 10)
    except ValueError:
        v = -1
    if not 0 <= v <= 0xFFFFFFFF:
        raise argparse.ArgumentTypeError(f"'{text}' is not a 32-bit policy hash (0x hex or decimal)")
    return v


def _node_id(text: str) -> int:
    v = _int(text)
    if not 0 <= v <= 63:
        raise argparse.ArgumentTypeError(f"node id {v} outside 0..63")
    return v


def _seconds(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = -1.0
    if not 0.0 < v <= 86400.0:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of seconds in (0, 86400]")
    return v


def parser() -> argparse.ArgumentParser:
    ap = cli.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0], epilog=EPILOG)
    ap.add_argument("--channel", default="vcan0",
                    help="the CAN bus, as python-can names it (socketcan: a network interface; default %(default)s)")
    ap.add_argument("--interface", default="socketcan",
                    help="python-can's interface, the kind of bus (socketcan, virtual, ...; default %(default)s)")
    ap.add_argument("--node", type=_node_id, default=0, help="controller node id, 0..63 (default 0)")
    ap.add_argument("--timeout", type=_seconds, default=bn.DEFAULT_TIMEOUT_S,
                    help="seconds to wait for an answer (default %(default)s)")
    ap.add_argument("--expect-hash", type=_hash, help="the policy hash the node must run before a motion command")
    ap.add_argument("--weights", type=Path, help="weights.h whose content hash the node must run (instead)")
    ap.add_argument("--yes", action="store_true", help="do not ask before a command that can move the axis")
    sub = ap.add_subparsers(dest="cmd", required=True, metavar="COMMAND")
    sub.add_parser("scan", help="list the nodes on the bus")
    sub.add_parser("info", help="identity and state of the node")
    sub.add_parser("faults", help="mode and latched faults by name: the core's, and the drive's (DriveTelemetry)")
    sub.add_parser("clear", help="clear latched faults (MOVES: a run resumes)")
    p = sub.add_parser("estop", help="assert the e-stop (or --release it)")
    p.add_argument("--release", action="store_true", help="release the e-stop instead (the node goes to FAULT)")
    sub.add_parser("stop", help="end the run (RUN -> IDLE)")
    sub.add_parser("reset", help="start a new run from the power-on state (MOVES once samples flow)")
    p = sub.add_parser("config", help="parameters in SI units: get [NAME...], set NAME VALUE, dump FILE, restore FILE, "
                                      "save, list")
    csub = p.add_subparsers(dest="config_cmd", required=True, metavar="ACTION")
    g = csub.add_parser("get", help="read parameters from the node, in SI units with their ranges")
    g.add_argument("names", nargs="*", help="parameter names or ids (default: all)")
    g.add_argument("--raw", action="store_true", help="print the integers the node stores (NAME VALUE), no units")
    s = csub.add_parser("set", help="write one parameter (IDLE or FAULT only; a refusal names its reason)")
    s.add_argument("name", help="parameter name or id (config list)")
    s.add_argument("value", help="the value in SI units (config get shows them), or with --raw the stored integer")
    s.add_argument("--raw", action="store_true", help="VALUE is the integer the node stores, in its firmware unit")
    d = csub.add_parser("dump", help="every parameter of the node into a JSON file (raw values and SI readings)")
    d.add_argument("file", type=Path, help="the JSON file to write (atomically)")
    r = csub.add_parser("restore", help="write every parameter of a dump back (the whole file checked first)")
    r.add_argument("file", type=Path, help="a config dump (pour-bench config dump)")
    csub.add_parser("save", help="store the node's parameters (its params= file, flash on the board)")
    csub.add_parser("list", help="the parameter names this DBC knows, with their units and ranges")
    p = sub.add_parser("tare", help="tare the scales at their present reading")
    p.add_argument("--scale", choices=["rotating", "target", "both"], default="both",
                   help="which load cell (default %(default)s)")
    sub.add_parser("zero", help="the encoder's present count becomes upright")
    p = sub.add_parser("log", help="record the bus as a candump -L log")
    p.add_argument("output", type=Path, help="the candump -L log to write (atomically)")
    p.add_argument("--seconds", type=_seconds, default=10.0, help="record this long (default %(default)s)")
    p = sub.add_parser("plot", help="live plot: θ, θ̇, torque, scales, mode and faults (--png to save)")
    p.add_argument("--seconds", type=_seconds, default=3600.0, help="stop after this long (default: an hour)")
    p.add_argument("--window", type=_seconds, default=10.0, help="seconds shown (default %(default)s)")
    p.add_argument("--encoder-bits", type=_int, default=17, help="the controller's encoder_bits (default 17)")
    p.add_argument("--png", type=Path, help="save the figure as a PNG at the end")
    p.add_argument("--replay", type=Path, help="plot a candump -L log (pour-bench log) instead of the bus")
    p.add_argument("--fast", action="store_true", help="--replay as fast as it draws, not at the log's pace")
    p.add_argument("--no-window", action="store_true", help="draw off-screen (with --png)")
    p = sub.add_parser("identify", help="the controller's identification experiment, logged (MOVES the axis)")
    p.add_argument("output", type=Path, help="the candump -L log to write (pour-sysid reads it)")
    p.add_argument("--kind", choices=["identify", "tilt"], default="identify",
                   help="identify: bucket EMPTY, steps and a chirp about 20 deg within -3..43 deg; tilt: with "
                        "water, to 90 deg at 0.1 rad/s and back (default %(default)s)")
    p.add_argument("--seconds", type=_seconds, default=60.0, help="give up after this long (default %(default)s)")
    p = sub.add_parser("calibrate", help="the drive's self-calibration: R, L, pole pairs, encoder direction and "
                                         "offset, stored by the node (MOVES the axis)")
    p.add_argument("--seconds", type=_seconds, default=bn.CALIBRATION_S,
                   help="wait this long for its outcome (default %(default)s)")
    sub.add_parser("calibration", help="read the calibration the node stores (read-only: no motion, in any mode)")
    return ap


def _expected_hash(a: argparse.Namespace) -> int:
    if a.weights is not None:
        try:
            return weights_h.parse_weights_h(a.weights).content_hash
        except (OSError, ValueError) as e:
            raise UsageError(f"--weights {a.weights}: {e}") from e
    if a.expect_hash is None:
        raise UsageError(f"'{a.cmd}' can move the axis: give the policy you expect with --expect-hash HASH or "
                            f"--weights weights.h")
    return a.expect_hash


def _confirm_motion(a: argparse.Namespace, n: bn.Node, want: int) -> None:
    st = n.check_protocol(a.timeout)
    assert st.identity is not None
    if st.identity.weights_hash != want:
        raise bn.BenchError(f"node {n.id} runs policy 0x{st.identity.weights_hash:08x}, not the expected "
                            f"0x{want:08x}: '{a.cmd}' refused")
    if a.yes:
        return
    if not sys.stdin.isatty():
        raise bn.BenchError(f"'{a.cmd}' can move the axis: confirm with --yes (no terminal to ask on)")
    answer = input(f"'{a.cmd}' can move the axis of node {n.id} ({MOTION[a.cmd]}; policy 0x{want:08x}). Type yes "
                   f"to go on: ")
    if answer.strip() != "yes":
        raise bn.BenchError(f"'{a.cmd}' not confirmed")


# Identity.InitStatus values a bench acts on (pour_status_t, pour/fixed.h).
INIT_STATUS = {
    -5: " (POUR_ECALIBRATION: no valid drive calibration; run pour-bench calibrate)",
    -7: " (POUR_EPARAMS: the stored parameters are refused)",
    -8: " (POUR_EALIGN: the stored electrical offset is not trusted after the reset; run pour-bench calibrate)",
}


def _print_state(st: bn.NodeState) -> None:
    print(f"node {st.node_id}: mode {st.mode}, faults {', '.join(st.faults) or 'none'}, "
          f"rx_dropped {st.rx_dropped}, overruns {st.overruns}, refused {st.refused}"
          + (", held (RUN waits for a Reset: pour-bench reset)" if st.held else ""))


def _print_drive(n: bn.Node, timeout: float) -> None:
    """The drive's faults by name, its currents and bus voltage, from a DriveTelemetry frame (one a heartbeat)."""
    if n.state is None or n.state.drive is None:
        try:
            n.bench.wait_for(n.id, lambda name, s: name == "DriveTelemetry", min(timeout, bn.HEARTBEAT_WAIT_S),
                             "with its drive's telemetry")
        except bn.NodeTimeout:
            pass
    drive = n.state.drive if n.state is not None else None
    print(f"node {n.id}: {drive.describe()}" if drive is not None
          else f"node {n.id}: no DriveTelemetry (a controller without a drive of its own)")


def _plot(a: argparse.Namespace) -> int:
    from pour.bench import plot
    if not 8 <= a.encoder_bits <= 24:
        raise UsageError(f"--encoder-bits {a.encoder_bits} outside 8..24")
    if a.png is not None:
        try:
            atomic.check_output_path(a.png, "--png")
        except ValueError as e:
            raise UsageError(str(e)) from e
    if a.no_window and a.png is None:
        raise UsageError("--no-window draws nothing to see: give --png FILE")
    if a.replay is not None and not a.replay.is_file():
        raise UsageError(f"--replay {a.replay}: no such file")
    db = bn.load_dbc()
    if a.replay is not None:
        used = plot.run(plot.replay(a.replay, paced=not a.fast), db, a.node, a.seconds, a.encoder_bits, a.window,
                        a.png, not a.no_window, hold=True)
    else:
        with bn.Bench(channel=a.channel, interface=a.interface) as bench:
            used = plot.run(bench.frames(a.seconds), db, a.node, a.seconds, a.encoder_bits, a.window, a.png,
                            not a.no_window)
    print(f"pour-bench plot: {used} frames of node {a.node}" + (f", figure in {a.png}" if a.png else ""))
    return 0


def _param_table() -> dict[str, bp.Param]:
    try:
        return bp.table()
    except SimError as e:
        raise bn.BenchError(f"the parameters' units and ranges come from libpoursim: {e}") from e


def _param(table: dict[str, bp.Param], n: bn.Node, name_or_id: str) -> bp.Param:
    name = n.bench.param_names.get(n.param_id(name_or_id), str(name_or_id))
    if name not in table:
        raise bn.BenchError(f"no parameter '{name_or_id}' in the firmware's table")
    return table[name]


def _config_value(a: argparse.Namespace, table: dict[str, bp.Param]) -> tuple[str, int, bp.Param | None]:
    """config set's parameter name and raw value, checked before the bus opens (UsageError: exit 2)."""
    if a.raw:
        return a.name, _int_arg(a.value, "VALUE"), None
    names = bn.param_names(bn.load_dbc())
    name = names.get(int(a.name), a.name) if a.name.isdigit() else a.name
    if name not in table:
        raise UsageError(f"no parameter '{a.name}' (config list names them)")
    try:
        value = float(a.value)
    except ValueError:
        raise UsageError(f"VALUE: '{a.value}' is not a number (in {table[name].si_unit or 'its unit'}; "
                         f"--raw for the stored integer)") from None
    try:
        return name, table[name].from_si(value), table[name]
    except ValueError as e:
        raise UsageError(str(e)) from None


def _config_restore(a: argparse.Namespace, n: bn.Node, values: dict[str, int]) -> None:
    # The node judges the set as a whole (theta_min < theta_max, ...): a write refused as INCONSISTENT waits
    # for the others and is tried again; any other refusal ends the restore.
    pending = list(values.items())
    while pending:
        deferred = []
        for name, raw in pending:
            try:
                n.set(name, raw, a.timeout)
            except bn.ParamRefused as e:
                if e.result != "INCONSISTENT":
                    raise
                deferred.append((name, raw))
        if len(deferred) == len(pending):
            name, raw = deferred[0]
            n.set(name, raw, a.timeout)  # raises the node's refusal, named
        pending = deferred
    print(f"node {n.id}: {len(values)} parameters restored from {a.file} (config save stores them)")


def _int_arg(text: str, what: str) -> int:
    try:
        return _int(text)
    except argparse.ArgumentTypeError as e:
        raise UsageError(f"{what}: {e}") from None


def run(a: argparse.Namespace) -> int:
    if a.cmd == "config" and a.config_cmd == "list":
        table = _param_table()
        for pid, name in bn.param_names(bn.load_dbc()).items():
            prm = table.get(name)
            default = f"{prm.to_si(prm.default):.6g} {prm.si_unit}".rstrip() if prm else ""
            print(f"{pid:3d} {name}" + (f"  [{prm.range_text()}; default {default}]" if prm else ""))
        return 0
    table: dict[str, bp.Param] = {}
    if a.cmd == "config" and not getattr(a, "raw", False) and a.config_cmd != "save":
        table = _param_table()
    if a.cmd == "config" and a.config_cmd == "set":
        set_name, set_raw, set_param = _config_value(a, table)
    if a.cmd == "config" and a.config_cmd == "restore":
        try:
            restore = bp.load_dump(a.file, table)
        except bp.ParamFileError as e:
            raise UsageError(str(e)) from e
    if a.cmd == "config" and a.config_cmd == "dump":
        try:
            atomic.check_output_path(a.file, "dump FILE")
        except ValueError as e:
            raise UsageError(str(e)) from e
    want = _expected_hash(a) if a.cmd in MOTION else None
    if a.cmd == "plot":
        return _plot(a)
    with bn.Bench(channel=a.channel, interface=a.interface) as bench:
        if a.cmd == "scan":
            for st in bench.scan(max(a.timeout, bn.HEARTBEAT_WAIT_S)).values():
                ident = st.identity
                extra = (f", policy 0x{ident.weights_hash:08x}, tau_max {ident.tau_max_nm:.2f} N.m, "
                         f"firmware {ident.fw_version}") if ident else ""
                print(f"node {st.node_id}: mode {st.mode}{extra}")
            return 0
        n = bench.node(a.node)
        if a.cmd == "info":
            st = n.info(a.timeout)
            assert st.identity is not None
            i = st.identity
            print(f"node {st.node_id}: policy 0x{i.weights_hash:08x}, tau_max {i.tau_max_nm:.2f} N.m, firmware "
                  f"{i.fw_version}, init status {i.init_status}{INIT_STATUS.get(i.init_status, '')}")
            if i.fw_version != bench.protocol:
                print(f"pour-bench: warning: firmware {i.fw_version} and this DBC (protocol {bench.protocol}) "
                      f"differ: some frames may be misread", file=sys.stderr)
            _print_state(st)
            _print_drive(n, a.timeout)
        elif a.cmd == "faults":
            _print_state(n.info(a.timeout))
            _print_drive(n, a.timeout)
        elif a.cmd == "estop":
            n.estop(not a.release)
            _print_state(n.wait_mode({"FAULT"} if a.release else {"ESTOP"}, a.timeout))
        elif a.cmd == "stop":
            _print_state(n.stop(a.timeout))
        elif a.cmd in ("clear", "reset"):
            assert want is not None
            _confirm_motion(a, n, want)
            n.clear(a.timeout) if a.cmd == "clear" else n.reset(a.timeout)
            st = n.wait_mode({"IDLE", "RUN"} if a.cmd == "clear" else {"IDLE", "RUN", "FAULT"}, a.timeout)
            _print_state(st)
        elif a.cmd == "config":
            if a.config_cmd == "get":
                names = a.names or [name for _, name in sorted(bench.param_names.items())]
                for name in names:
                    raw = n.get(name, a.timeout)
                    print(f"{name} {raw}" if a.raw else _param(table, n, name).describe(raw))
            elif a.config_cmd == "set":
                now = n.set(set_name, set_raw, a.timeout)
                print(set_param.describe(now) if set_param is not None else f"{set_name} {now}")
            elif a.config_cmd == "dump":
                raw = {name: n.get(pid, a.timeout) for pid, name in sorted(bench.param_names.items())}
                bp.dump(a.file, n.id, raw, table)
                print(f"{a.file}: {len(raw)} parameters of node {n.id}")
            elif a.config_cmd == "restore":
                _config_restore(a, n, restore)
            else:
                n.save(a.timeout)
                print(f"node {n.id}: parameters saved")
        elif a.cmd == "tare":
            scales = {"rotating": bn.TARE_ROTATING, "target": bn.TARE_TARGET}.get(a.scale, 3)
            n.tare(scales, a.timeout)
            print(f"node {n.id}: {a.scale} tared")
        elif a.cmd == "zero":
            n.zero(a.timeout)
            print(f"node {n.id}: encoder zeroed")
        elif a.cmd == "identify":
            assert want is not None
            _confirm_motion(a, n, want)
            count, ended = n.identify(a.output, a.kind, a.seconds)
            print(f"{a.output}: {count} frames; the {a.kind} experiment ended: {ended} (bucket held)")
        elif a.cmd == "calibrate":
            assert want is not None
            _confirm_motion(a, n, want)
            print(f"node {n.id}: calibrated: {n.calibrate(a.seconds, a.timeout).describe()}")
        elif a.cmd == "calibration":
            n.check_protocol(a.timeout)  # the frame's layout is this DBC's: another protocol would be misread
            print(f"node {n.id}: {n.read_calibration(a.timeout).describe()}")
        elif a.cmd == "log":
            count = n.record(a.output, a.seconds)
            print(f"{a.output}: {count} frames in {a.seconds:g} s")
    return 0


def main(argv: list[str] | None = None) -> int:
    a = parser().parse_args(argv)
    try:
        return run(a)
    except UsageError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    except (bn.BenchError, ValueError) as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
