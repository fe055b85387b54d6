# SPDX-License-Identifier: MIT
"""The docs' commands, run as a newcomer would after ./scripts/demo.sh, in a workspace of
their own (outputs land there, not in the checkout; build/, .venv/, configs/ and policy/ are the
checkout's, policy/ copied). Every command line of the blocks below is either run or listed in SKIPPED
with the reason, so a new command in the docs has to be classified here.

Cheap variants, named in CHEAPER: the training and evaluation commands run with fewer iterations and
episodes than written (the full ones take minutes); each still runs its config, the simulator library,
the firmware core and the files the next command reads."""
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import BUILD_DIR, SOURCE_DIR

# Substitutions that make a written command cheap; (pattern, replacement, why).
CHEAPER = [
    (r"^(\.venv/bin/pour-train [^#]*?)(\s+#.*)?$", r"\1 --iterations 1", "a full stage trains for 75-90 s"),
    (r"^(\.venv/bin/pour-eval robust [^#]*?)(\s+#.*)?$", r"\1 --nominal-episodes 2 --edge-episodes 1",
     "the full table is 2 min of pours"),
    (r"--episodes 20\b", "--episodes 2", "20 held-out pours where 2 show the command works"),
]
# Commands whose exit status 1 is a verdict, not a failure: (prefix, what stdout then holds, why).
VERDICT_1 = [(".venv/bin/pour-eval robust", "| scene |",
              "exit 1 says a bar is missed, which 2 episodes of a one-iteration policy may do; the table is printed")]
# Command lines that are not run, with the reason (matched as prefixes of the logical line).
SKIPPED = {
    "./scripts/build.sh": "rebuilds the checkout this test runs from (its programs are what the test uses); "
                          "test_cli_conventions runs its --help",
    ".venv/bin/pour-train configs/train/pour2.toml": "the binary policy: the same commands as the 11-level one",
    ".venv/bin/pour-export runs/pour2": "needs the binary policy's run (above)",
}


def blocks(md: Path) -> list[list[str]]:
    """The fenced code blocks of md, each as logical command lines: continuations joined, comments and
    blank lines dropped."""
    out, cur, inside = [], None, False
    for line in md.read_text().splitlines():
        if line.startswith("```"):
            inside = not inside
            if inside:
                cur = []
            else:
                out.append(cur)
            continue
        if inside:
            cur.append(line)
    result = []
    for b in out:
        logical, acc = [], ""
        for line in b:
            acc += line.rstrip()
            if acc.endswith("\\"):
                acc = acc[:-1] + " "
                continue
            stripped = acc.strip()
            acc = ""
            if stripped and not stripped.startswith("#"):
                logical.append(re.sub(r"\s+", " ", stripped))
        result.append(logical)
    return result


def block_with(md: Path, needle: str) -> list[str]:
    (b,) = [b for b in blocks(md) if any(needle in c for c in b)][:1]
    return b


def make_workspace(root: Path) -> Path:
    """A checkout's layout for outputs: runs/ and out/ appear as the commands make them; results/ exists in
    a checkout, so it does here (empty)."""
    ws = root / "ws"
    ws.mkdir()
    (ws / "results").mkdir()
    for name in (".venv", "configs"):
        (ws / name).symlink_to(SOURCE_DIR / name)
    (ws / "build").mkdir()
    (ws / "build" / "host").symlink_to(BUILD_DIR)
    shutil.copytree(SOURCE_DIR / "policy", ws / "policy")
    return ws


@pytest.fixture(scope="module")
def ws(tmp_path_factory) -> Path:
    """One for the training commands: the training notes' first commands are the guide's, and a pour-train
    on a finished run folder resumes it (nothing to train)."""
    return make_workspace(tmp_path_factory.mktemp("docs"))


def run_commands(ws: Path, commands: list[str]) -> list[str]:
    ran = []
    env = {k: v for k, v in os.environ.items() if k not in ("POUR_SIM_LIB",)}
    env["PATH"] = f"{ws / '.venv' / 'bin'}:{env['PATH']}"
    for cmd in commands:
        if any(cmd.startswith(p) for p in SKIPPED):
            continue
        cheap = cmd
        for pattern, repl, _ in CHEAPER:
            cheap = re.sub(pattern, repl, cheap)
        r = subprocess.run(["bash", "-c", "set -euo pipefail; " + cheap], cwd=ws, env=env, capture_output=True,
                           text=True, timeout=600)
        verdict = any(cmd.startswith(p) and table in r.stdout for p, table, _ in VERDICT_1)
        ok = r.returncode == 0 or (r.returncode == 1 and verdict)
        assert ok and "Traceback" not in r.stderr, f"{cmd!r} (run as {cheap!r}):\n{r.stderr[-2000:]}"
        ran.append(cmd)
    return ran


TRAINING = SOURCE_DIR / "docs" / "training.md"
NOTES = SOURCE_DIR / "docs" / "notes" / "training-2026-12.md"


def test_training_guide_block_runs_in_order(ws):
    """docs/training.md "Train, export, evaluate": the chain's three runs, export, evaluate, pour with the new
    header."""
    commands = block_with(TRAINING, "pour-train configs/train/pour11_stage1.toml")
    ran = run_commands(ws, commands)
    assert len(ran) >= 5
    assert (ws / "runs" / "pour11" / "policy.json").is_file() and (ws / "results" / "robustness" / "robustness.md").is_file()
    assert (ws / "policy" / "weights.h").read_bytes() != (SOURCE_DIR / "policy" / "weights.h").read_bytes()


def test_training_doc_first_commands_run(ws):
    """The training notes' "Commands behind the results": everything before the convergence runs (which train
    11 more runs and feed pour-plots and pour-results: about 25 minutes)."""
    commands = block_with(NOTES, "pour-results --init")
    first = commands[:next(i for i, c in enumerate(commands) if c.startswith("for "))]
    ran = run_commands(ws, first)
    assert any("pour-eval agree" in c for c in ran) and any("host_sim" in c for c in ran)


def test_bench_doc_one_command_pour_runs(tmp_path):
    """docs/bench.md: the whole pour over LCM in one command, with the shipped policy that pour_controller
    compiles in (the recipe's steps run until Ctrl-C or need a display; tests/python/test_lcm_*.py run them
    one by one)."""
    ws = make_workspace(tmp_path)
    text = (SOURCE_DIR / "docs" / "bench.md").read_text()
    (cmd,) = re.findall(r"`(\.venv/bin/pour-lcm-run -- [^`]+)`", text)
    run_commands(ws, [cmd])
    assert (ws / "pour.gif").stat().st_size > 10000


def test_every_cheaper_and_skipped_entry_is_used():
    """No stale entries: each substitution and each skip matches a command of the blocks above."""
    commands = (block_with(TRAINING, "pour-train configs/train/pour11_stage1.toml")
                + block_with(NOTES, "pour-results --init"))
    for pattern, _, why in CHEAPER:
        assert any(re.search(pattern, c) for c in commands), why
    for prefix in SKIPPED:
        assert any(c.startswith(prefix) for c in commands), prefix
