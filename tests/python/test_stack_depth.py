# SPDX-License-Identifier: MIT
"""scripts/lib/stack_depth.py: the deepest chain of frames in a GCC call graph (-fcallgraph-info=su), which
scripts/bench.sh reports as the Cortex-M4 image's stack; and its refusals of what it cannot bound."""
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "lib" / "stack_depth.py"


def node(name: str, frame: int | None, suffix: str = "") -> str:
    size = "<built-in>" if frame is None else f"f.c:1:1\\n{frame} bytes (static)"
    return f'node: {{ title: "u.o:{name}{suffix}" label: "{name}{suffix and suffix[:-2]}\\n{size}" }}'


def edge(src: str, dst: str) -> str:
    return f'edge: {{ sourcename: "u.o:{src}" targetname: "{dst if dst.startswith("__") else "u.o:" + dst}" }}'


def graph(tmp_path: Path, *lines: str) -> Path:
    p = tmp_path / "image.ltrans0.ltrans.ci"
    p.write_text('graph: { title: "u.o"\n' + "\n".join(lines) + "\n}\n")
    return p


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=30)


def test_the_deepest_chain_is_summed_and_named(tmp_path):
    g = graph(tmp_path, node("main", 40), node("step", 64, ".constprop.0"), node("kernel", 176), node("small", 8),
              node("memset", None), edge("main", "step.constprop.0"), edge("main", "small"),
              edge("step.constprop.0", "kernel"), edge("step.constprop.0", "__builtin_memset"))
    r = run(str(g), "--root", "main", "--root", "step")
    assert r.returncode == 0, r.stderr
    main, step = r.stdout.splitlines()
    assert main.startswith("main 280 main>step>kernel")
    assert step.startswith("step 240 step>kernel")


def test_an_indirect_call_takes_the_worst_function_nobody_calls(tmp_path):
    g = graph(tmp_path, node("main", 16), node("hook", 96), node("isr", 24), node("__indirect_call", None),
              edge("main", "__indirect_call"))
    # isr has no caller either, but it is a vector entry: never an indirect target.
    r = run(str(g), "--root", "main", "--entry", "isr")
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("main 112 main>hook")


def test_a_library_helper_is_listed_as_uncounted(tmp_path):
    g = graph(tmp_path, node("main", 16), edge("main", "__aeabi_ldivmod"))
    r = run(str(g), "--root", "main")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().endswith("uncounted: __aeabi_ldivmod")


def test_recursion_is_refused(tmp_path):
    g = graph(tmp_path, node("a", 8), node("b", 8), edge("a", "b"), edge("b", "a"))
    r = run(str(g), "--root", "a")
    assert r.returncode == 2 and "recursion" in r.stderr and not r.stdout


def test_a_root_that_was_inlined_away_is_refused(tmp_path):
    g = graph(tmp_path, node("main", 8))
    r = run(str(g), "--root", "pour_control_step")
    assert r.returncode == 2 and "pour_control_step is not in the call graph" in r.stderr


def test_a_dynamic_frame_is_refused(tmp_path):
    g = tmp_path / "d.ci"
    g.write_text('graph: { title: "u.o"\nnode: { title: "u.o:f" label: "f\\nf.c:1:1\\n16 bytes (dynamic)" }\n}\n')
    r = run(str(g), "--root", "f")
    assert r.returncode == 2 and "dynamic" in r.stderr


def test_a_file_that_is_not_a_call_graph_is_refused(tmp_path):
    bad = tmp_path / "x.su"
    bad.write_text("main.c:3:5:main\t48\tstatic\n")
    r = run(str(bad), "--root", "main")
    assert r.returncode == 2 and "not a GCC call graph" in r.stderr
    r = run(str(tmp_path / "missing.ci"), "--root", "main")
    assert r.returncode == 2 and "cannot read" in r.stderr
