# SPDX-License-Identifier: MIT
"""Bus load of the pour CAN protocol, from the DBC: frame lengths in bits (classic CAN, 11-bit ids), with
and without worst-case bit stuffing, at the cycle times the DBC declares (GenMsgCycleTime).

Frame bits (classic base frame, n data bytes): SOF 1 + id 11 + RTR 1 + IDE 1 + r0 1 + DLC 4 + data 8n +
CRC 15 = 34 + 8n bits that can be stuffed, then CRC delimiter, ACK slot and delimiter, EOF 7 and the
3-bit interframe space: 47 + 8n bits in all. Worst-case stuffing adds floor((34 + 8n - 1) / 4) bits
(Davis, Burns, Bril, Lukkien: "Controller Area Network (CAN) schedulability analysis", 2007).
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import cantools

from pour import cli
from pour.can.dbc import default_dbc

BITRATE = 1_000_000
BAR = 0.50


def frame_bits(n_bytes: int, stuffing: bool = True) -> int:
    """Bits on the wire for one classic CAN data frame with an 11-bit id, including the interframe space."""
    if not 0 <= n_bytes <= 8:
        raise ValueError(f"classic CAN carries 0..8 data bytes, not {n_bytes}")
    bits = 47 + 8 * n_bytes
    return bits + ((34 + 8 * n_bytes - 1) // 4 if stuffing else 0)


def _crc15(bits: list[int]) -> int:
    crc = 0
    for b in bits:
        nxt = b ^ ((crc >> 14) & 1)
        crc = (crc << 1) & 0x7FFF
        if nxt:
            crc ^= 0x4599  # CAN's CRC-15 polynomial
    return crc


def wire_bits(frame_id: int, data: bytes) -> int:
    """Exact bits on the wire of one classic base data frame: its real bit stream (CRC-15 included) with
    stuffing, plus the fixed tail and the interframe space."""
    if not 0 <= frame_id <= 0x7FF or len(data) > 8:
        raise ValueError(f"not a classic 11-bit frame: id 0x{frame_id:x}, {len(data)} bytes")
    bits = [0] + [(frame_id >> (10 - i)) & 1 for i in range(11)] + [0, 0, 0]
    bits += [(len(data) >> (3 - i)) & 1 for i in range(4)]
    for byte in data:
        bits += [(byte >> (7 - i)) & 1 for i in range(8)]
    crc = _crc15(bits)
    bits += [(crc >> (14 - i)) & 1 for i in range(15)]
    stuffed, run, last = 0, 0, -1
    for b in bits:
        run = run + 1 if b == last else 1
        last = b
        if run == 5:  # a stuff bit of the opposite level, which starts the next run
            stuffed += 1
            last, run = 1 - b, 1
    return len(bits) + stuffed + 13


def measured(candump_log: Path, dbc: Path | None = None) -> tuple[int, int, int]:
    """From a `candump -L` capture: (frames, exact bits on the wire, control ticks = Torque frames)."""
    torque_cmd = cantools.database.load_file(str(dbc or default_dbc())).get_message_by_name("Torque").frame_id
    frames = bits = ticks = 0
    for line in candump_log.read_text().splitlines():
        parts = line.split()
        if len(parts) < 3 or "#" not in parts[2]:
            continue
        ident, payload = parts[2].split("#", 1)
        frame_id = int(ident, 16)
        frames += 1
        bits += wire_bits(frame_id, bytes.fromhex(payload))
        ticks += (frame_id & 0x1F) == torque_cmd
    return frames, bits, ticks


@dataclass
class Row:
    name: str
    dlc: int
    rate_hz: float
    bits: int
    bits_nominal: int

    @property
    def load(self) -> float:
        return self.rate_hz * self.bits / BITRATE


def cyclic_messages(dbc: Path | None = None, heartbeat_ms: float | None = None) -> list[Row]:
    """One row per message with a cycle time in the DBC (heartbeat_ms overrides the heartbeat's, and those of
    the identity and drive-telemetry frames, which go out with every heartbeat)."""
    db = cantools.database.load_file(str(dbc or default_dbc()))
    rows = []
    for m in db.messages:
        cycle = m.cycle_time
        if m.name in ("Heartbeat", "Identity", "DriveTelemetry") and heartbeat_ms is not None:
            cycle = heartbeat_ms
        if not cycle:
            continue  # event messages (e-stop, clear-errors) add nothing steady
        rows.append(Row(m.name, m.length, 1000.0 / cycle, frame_bits(m.length), frame_bits(m.length, False)))
    return rows


def report(rows: list[Row]) -> str:
    lines = [f"{'message':<14} {'DLC':>3} {'rate':>8} {'bits':>5} {'bits*':>5} {'load':>7}"]
    for r in rows:
        lines.append(f"{r.name:<14} {r.dlc:>3} {r.rate_hz:>6.0f}Hz {r.bits_nominal:>5} {r.bits:>5} {100 * r.load:>6.2f}%")
    total = sum(r.load for r in rows)
    nominal = sum(r.rate_hz * r.bits_nominal for r in rows) / BITRATE
    lines.append(f"bus load at 1 Mbit/s: {100 * total:.1f} % worst case (bits* = with worst-case stuffing), "
                 f"{100 * nominal:.1f} % without stuffing; bar {100 * BAR:.0f} %: "
                 f"{'ok' if total <= BAR else 'OVER'}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-can-bus-load", description=__doc__.splitlines()[0])
    ap.add_argument("--dbc", help="DBC file (default: can/pour.dbc, or the installed package's copy)")
    ap.add_argument("--heartbeat-ms", type=float, default=None, help="heartbeat period instead of the DBC's [ms]")
    ap.add_argument("--candump", help="also measure a `candump -L` capture: exact bits per control tick")
    args = ap.parse_args(argv)
    if args.heartbeat_ms is not None and not args.heartbeat_ms > 0:
        print(f"pour-can-bus-load: error: --heartbeat-ms must be positive, got {args.heartbeat_ms}", file=sys.stderr)
        return 2
    try:
        dbc = Path(args.dbc) if args.dbc else default_dbc()
        rows = cyclic_messages(dbc, args.heartbeat_ms)
    except (OSError, cantools.database.UnsupportedDatabaseFormatError) as e:
        print(f"pour-can-bus-load: error: cannot read {args.dbc or 'the DBC'}: {e}", file=sys.stderr)
        return 2
    print(report(rows))
    if args.candump:
        try:
            frames, bits, ticks = measured(Path(args.candump), dbc)
        except (OSError, ValueError) as e:
            print(f"pour-can-bus-load: error: cannot read {args.candump}: {e}", file=sys.stderr)
            return 2
        if ticks == 0:
            print(f"pour-can-bus-load: error: {args.candump} has no Torque frame", file=sys.stderr)
            return 2
        print(f"measured ({args.candump}): {frames} frames over {ticks} ticks, {bits / ticks:.1f} bits per 1 ms "
              f"tick with exact stuffing = {100 * bits / ticks * 1000 / BITRATE:.1f} % of 1 Mbit/s at 1 kHz")
    return 0


if __name__ == "__main__":
    sys.exit(main())
