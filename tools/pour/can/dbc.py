# SPDX-License-Identifier: MIT
"""The pour CAN protocol's DBC (can/pour.dbc, written for node 0) and its variant for any node id.

Ids follow the ODrive rule: ``id = (node_id << 5) | cmd``, node_id 0..63, cmd 0..31. ``pour-can-dbc
--node N`` writes the DBC of node N, so that ``candump -L can0 | python -m cantools decode FILE``
decodes a controller configured with that node id.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

from pour import atomic, cli, paths

NODE_ID_MAX = 63
CMD_MASK = 0x1F
NODE_SHIFT = 5



def default_dbc() -> Path:
    """The protocol's DBC (can/pour.dbc, or the installed package's copy); FileNotFoundError if neither."""
    return paths.data_file("pour.dbc")


def protocol_version(db_version: str | None) -> int:
    """The protocol number of a DBC's VERSION string ("pour CAN protocol N"), which a node reports as
    Identity's FwVersion; ValueError for any other string."""
    m = re.fullmatch(r"pour CAN protocol (\d+)", db_version or "")
    if m is None:
        raise ValueError(f"DBC VERSION {db_version!r} is not 'pour CAN protocol N'")
    return int(m.group(1))


def can_id(node_id: int, cmd: int) -> int:
    """Frame id of cmd for node_id."""
    check_node_id(node_id)
    if not 0 <= cmd <= CMD_MASK:
        raise ValueError(f"cmd id {cmd} outside 0..{CMD_MASK}")
    return (node_id << NODE_SHIFT) | cmd


def check_node_id(node_id: int) -> int:
    if isinstance(node_id, bool) or not isinstance(node_id, int) or not 0 <= node_id <= NODE_ID_MAX:
        raise ValueError(f"node id {node_id!r} outside 0..{NODE_ID_MAX}")
    return node_id


_ID_LINE = re.compile(r"^(BO_|CM_ BO_|CM_ SG_|BA_ \"[A-Za-z]+\" BO_|VAL_) (\d+)\b", re.MULTILINE)


def dbc_for_node(node_id: int, source: Path | None = None) -> str:
    """The DBC text for node_id: every frame id of the node-0 file (default_dbc()), with the node id in bits
    5..10."""
    check_node_id(node_id)
    source = source or default_dbc()
    text = source.read_text(encoding="ascii")

    def shift(m: re.Match[str]) -> str:
        cmd = int(m.group(2))
        if cmd > CMD_MASK:
            raise ValueError(f"{source}: frame id {cmd} is not a node-0 cmd id (0..{CMD_MASK})")
        return f"{m.group(1)} {can_id(node_id, cmd)}"

    out = _ID_LINE.sub(shift, text)
    return out.replace("This file is for node id 0.", f"This file is for node id {node_id}.")


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-can-dbc", description=__doc__.splitlines()[0])
    ap.add_argument("--node", required=True, help="controller node id, 0..63")
    ap.add_argument("-o", "--out", "--output", dest="output", help="file to write (default: standard output)")
    args = ap.parse_args(argv)
    try:
        node_id = int(args.node, 0)
        text = dbc_for_node(node_id)
    except (ValueError, OSError) as e:
        print(f"pour-can-dbc: error: {e}", file=sys.stderr)
        return 2
    if args.output:
        try:
            atomic.write_atomic(Path(args.output), text)
        except OSError as e:
            print(f"pour-can-dbc: error: cannot write {args.output}: {e}", file=sys.stderr)
            return 1
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
