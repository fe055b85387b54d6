# SPDX-License-Identifier: MIT
"""One flag grammar and one set of exit statuses across pour's programs: 0 done, 1 a failure while running,
2 bad input (the command line or a file it names), each documented in --help; numbers are decimal."""
import os
import subprocess
import sys

import pytest


def _run(*argv, env=None, timeout=60):
    return subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


@pytest.fixture
def bin_dir(build_dir):
    return build_dir / "bin"


@pytest.mark.parametrize("program", ["host_sim", "pour_controller", "can_bridge", "pour.policy.export",
                                     "pour.eval.render", "pour.bench.cli"])
def test_help_documents_the_exit_statuses(bin_dir, program):
    argv = [sys.executable, "-m", program] if program.startswith("pour.") else [bin_dir / program]
    r = _run(*argv, "--help")
    text = " ".join(r.stdout.lower().split())
    assert r.returncode == 0 and "exit status" in text, r.stdout
    assert "1 a failure while running" in text or "1 the write failed" in text or "1 a write failed" in text
    assert "2 bad" in text


def test_node_ids_are_decimal_everywhere(bin_dir):
    # 064 is 52 in octal (a valid node) but 64 in decimal (out of range): both programs must refuse it.
    r = _run(bin_dir / "can_bridge", "--channel", "nosuchcan0", "--node", "064")
    assert r.returncode == 2 and "--node needs an integer in [0, 63], got '064'" in r.stderr, r.stderr
    r = _run(bin_dir / "pour_controller", "--io", "can:nosuchcan0,node=064")
    assert r.returncode == 2 and "node needs an integer in [0, 63], got '064'" in r.stderr, r.stderr
    # 010 is node 10 for both: accepted, then the missing interface is a failure while running.
    for argv in ([bin_dir / "can_bridge", "--channel", "nosuchcan0", "--node", "010"],
                 [bin_dir / "pour_controller", "--io", "can:nosuchcan0,node=010"]):
        r = _run(*argv)
        assert r.returncode == 1 and ("no CAN support" in r.stderr or "no such CAN interface" in r.stderr), r.stderr


@pytest.mark.parametrize("io", ["bogus", "can:", "can:vcan0,node=x", "can:vcan0,speed=1"])
def test_a_bad_transport_spec_is_a_bad_command_line(bin_dir, io):
    r = _run(bin_dir / "pour_controller", "--io", io)
    assert r.returncode == 2 and r.stderr.startswith("pour_controller:"), r.stderr


def test_host_sim_bad_input_is_2_and_a_failed_renderer_1(bin_dir, tmp_path):
    hs = bin_dir / "host_sim"
    assert _run(hs, "--baseline", "nope").returncode == 2
    assert _run(hs, "--policy", tmp_path / "missing.h").returncode == 2
    r = _run(hs, "--baseline", "full", "--set", "episode_s=0.05", "--render", tmp_path / "x.gif",
             env={"POUR_RENDER": "/bin/false"})
    assert r.returncode == 1 and "renderer" in r.stderr, r.stderr


@pytest.mark.parametrize("env", [{"POUR_RENDER": "/nonexistent/pour-render"}, {"POUR_RENDER": "no-such-renderer"},
                                 {"POUR_RENDER": "", "PATH": "/usr/bin:/bin"}])
def test_host_sim_without_its_renderer_refuses_before_the_run(bin_dir, tmp_path, env):
    # pour-render is found through $POUR_RENDER, else on PATH, and checked with the outputs: one line, exit 2,
    # nothing run (no episode line) and nothing written.
    r = _run(bin_dir / "host_sim", "--baseline", "full", "--csv", tmp_path / "x.csv", "--render", tmp_path / "x.gif",
             env=env)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("host_sim: --render needs the renderer"), r.stderr
    assert (env.get("POUR_RENDER") or "pour-render") in lines[0] and "PATH" in lines[0]
    assert r.stdout == "" and list(tmp_path.iterdir()) == []
