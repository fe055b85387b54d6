# SPDX-License-Identifier: MIT
"""pour-lcm-run: the pour as two processes over LCM, in one command.

    pour-lcm-run [--realtime] [--url URL] [--build-dir DIR] -- HOST_SIM_ARGS...
    pour-lcm-run -- --policy policy/weights.h --render pour.gif

Starts pour_controller (lockstep, or its own 1 kHz clock with --realtime) on a private LCM URL, runs
host_sim --lcm on the same URL with the given arguments, stops the controller and prints both
summaries. The exit status is host_sim's (3: the controller did not answer).
"""
from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
from pathlib import Path

from pour import cli, paths


def find_binary(name: str, build_dir: str | None) -> Path:
    """NAME in a build tree's bin/ (pour.paths.build_dirs order)."""
    p = paths.binary(name, build_dir)
    if p is not None:
        return p
    dirs = paths.build_dirs(build_dir)
    raise SystemExit(f"error: {name} not found under {', '.join(map(str, dirs))}; build first "
                     "(cmake --workflow --preset host)")


def private_url() -> str:
    """A port of this process's own, so that two runs on one machine do not hear each other."""
    return f"udpm://239.255.76.67:{20000 + os.getpid() % 20000}?ttl=0"


def main(argv: list[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-lcm-run", description=__doc__.split("\n\n")[0])
    ap.add_argument("--realtime", action="store_true", help="1 kHz wall clock on both sides")
    ap.add_argument("--lcm", "--url", dest="url", metavar="URL", help="LCM URL (default: a private port on loopback)")
    ap.add_argument("--build-dir", help="CMake build tree (default $POUR_BUILD_DIR or build/host)")
    ap.add_argument("host_sim_args", nargs=argparse.REMAINDER, help="arguments for host_sim, after --")
    a = ap.parse_args(argv)
    rest = a.host_sim_args[1:] if a.host_sim_args[:1] == ["--"] else a.host_sim_args
    if "--lcm" in rest or "--realtime" in rest:
        ap.error("give --lcm/--realtime to pour-lcm-run, not to host_sim")
    controller, host_sim = find_binary("pour_controller", a.build_dir), find_binary("host_sim", a.build_dir)
    url = a.url or private_url()
    ctl_args = [str(controller), "--io", f"lcm:{url}"] + ([] if a.realtime else ["--lockstep"])
    # The controller's own messages matter only if the pour failed: after a good pour its input goes
    # quiet (host_sim may still be rendering), which it reports as a stale-input fault.
    ctl = subprocess.Popen(ctl_args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        hs_args = [str(host_sim), *rest, "--lcm", url] + (["--realtime"] if a.realtime else [])
        # host_sim --render runs pour-render: the one installed beside this Python, unless told otherwise.
        env = dict(os.environ)
        renderer = Path(sys.executable).with_name("pour-render")
        if "POUR_RENDER" not in env and renderer.exists():
            env["POUR_RENDER"] = str(renderer)
        rc = subprocess.call(hs_args, env=env)
    finally:
        if ctl.poll() is None:
            ctl.send_signal(signal.SIGINT)
        try:
            out, err = ctl.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            ctl.kill()
            out, err = ctl.communicate()
    sys.stdout.write(out)
    if rc != 0:
        sys.stderr.write(err)
    return rc


if __name__ == "__main__":
    sys.exit(main())
