# SPDX-License-Identifier: MIT
"""pour-lcm-cmd: send an operator command to pour_controller on POUR_COMMAND.

    pour-lcm-cmd --clear          # clear latched faults (acted on once the e-stop is released)
    pour-lcm-cmd --estop          # assert the e-stop: zero torque until released
    pour-lcm-cmd --release        # release the e-stop (the controller then stays in FAULT until --clear)
    pour-lcm-cmd --new-run        # stop the run and start a new one (RUN -> IDLE, then a reset)
"""
from __future__ import annotations

import sys
import time

from pour import cli
from pour.lcm import channels, messages


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-lcm-cmd", description=__doc__.split("\n\n")[0])
    ap.add_argument("--lcm", "--url", dest="url", metavar="URL", default=channels.DEFAULT_URL, help="LCM URL (default %(default)s)")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--clear", action="store_true", help="clear latched faults")
    g.add_argument("--estop", action="store_true", help="assert the e-stop")
    g.add_argument("--release", action="store_true", help="release the e-stop")
    g.add_argument("--new-run", action="store_true", help="stop the run and start a new one (stop + reset)")
    a = ap.parse_args(argv)
    import lcm

    m = messages.load()
    msg = m.command_t()
    msg.utime = int(time.time() * 1e6)
    msg.estop = bool(a.estop)
    msg.clear_faults = bool(a.clear)
    msg.stop = msg.reset = bool(a.new_run)
    try:
        lc = lcm.LCM(a.url)
    except RuntimeError as e:
        print(f"pour-lcm-cmd: error: cannot open LCM at {a.url}: {e}", file=sys.stderr)
        return 1
    lc.publish(channels.COMMAND, msg.encode())
    what = "clear_faults" if a.clear else "estop" if a.estop else "stop + reset" if a.new_run else "release"
    print(f"pour-lcm-cmd: sent {what} on {channels.COMMAND}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
