# SPDX-License-Identifier: MIT
"""scripts/lib/stack_depth.py: the deepest chain of frames in a GCC call graph (-fcallgraph-info=su), which
scripts/bench.sh reports as the Cortex-M4 image's stack; and its refusals of what it cannot bound."""
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "lib" / "stack_depth.py"
sys.path.insert(0, str(SCRIPT.parent))
from stack_depth import HELPER_FRAMES  # noqa: E402


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


def test_a_library_helper_of_unknown_frame_is_listed_as_uncounted(tmp_path):
    g = graph(tmp_path, node("main", 16), edge("main", "__aeabi_llsr"))
    r = run(str(g), "--root", "main")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "main 16 main>__aeabi_llsr uncounted: __aeabi_llsr"


def test_a_library_helper_of_known_frame_is_counted(tmp_path):
    # As the image's graph has them: a node without a size, called by its name from another unit or this one.
    g = graph(tmp_path, node("main", 16), node("scale", 24), node("memset", None),
              edge("main", "scale"), edge("main", "__builtin_memset"), edge("scale", "__aeabi_ldivmod"))
    r = run(str(g), "--root", "main")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"main {16 + 24 + HELPER_FRAMES['__aeabi_ldivmod']} main>scale>__aeabi_ldivmod"


PUSH = re.compile(r"\t(?:push(?:\.w)?|stmdb(?:\.w)?\tsp!,)\s*\{([^}]*)\}")
SUB_SP = re.compile(r"\tsub(?:\.w)?\tsp, (?:sp, )?#(\d+)")
PRE_INDEXED = re.compile(r"\tstr[a-z.]*\t[^[]*\[sp, #-(\d+)\]!")
CALL = re.compile(r"\t(?:bl|b\.w|b)\t[0-9a-f]+ <([^+>]+)>")
SYMBOL = re.compile(r"^([0-9a-f]+) [ a-zA-Z]* F \.text\t[0-9a-f]+ (?:\.hidden )?(\S+)$")
LABEL = re.compile(r"^([0-9a-f]+) <([^>]+)>:$")


def library_depths(objdump_dt: str) -> Callable[[str], int]:
    """The deepest stack of each function in `objdump -dt` text of an archive: every stack decrement in its
    body (an upper bound when none repeats in a loop, as in these helpers) over the deepest function it calls
    or branches to; names that share an address in one member (__aeabi_ldiv0, __aeabi_idiv0) are one."""
    own: dict[str, int] = {}
    calls: dict[str, set[str]] = {}
    alias: dict[str, str] = {}
    at: dict[str, list[str]] = {}  # this member's functions by address
    fn = ""
    for line in objdump_dt.splitlines():
        if "file format" in line:
            at, fn = {}, ""
        elif m := SYMBOL.match(line):
            at.setdefault(m[1], []).append(m[2])
        elif m := LABEL.match(line):
            fn = m[2]
            own.setdefault(fn, 0)
            calls.setdefault(fn, set())
            for name in at.get(m[1], []):
                alias.setdefault(name, fn)
        elif fn:
            if m := PUSH.search(line):
                own[fn] += 4 * len(m[1].split(","))
            elif m := SUB_SP.search(line) or PRE_INDEXED.search(line):
                own[fn] += int(m[1])
            if (m := CALL.search(line)) and m[1] != fn:
                calls[fn].add(m[1])

    def depth(f: str, seen: frozenset[str] = frozenset()) -> int:
        f = alias.get(f, f)
        assert f not in seen, f"recursion through {f}"
        return own[f] + max((depth(c, seen | {f}) for c in calls[f]), default=0)

    return depth


def test_the_helper_frames_are_those_of_the_libraries_the_image_links():
    flags = ["-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=soft"]
    gcc = ["arm-none-eabi-gcc", *flags]
    libgcc = subprocess.run([*gcc, "-print-libgcc-file-name"], capture_output=True, text=True, check=True)
    libc = subprocess.run([*gcc, "-print-file-name=libc_nano.a"], capture_output=True, text=True, check=True)
    text = "".join(subprocess.run(["arm-none-eabi-objdump", "-dt", lib.stdout.strip()], capture_output=True,
                                  text=True, check=True).stdout for lib in (libgcc, libc))
    depth = library_depths(text)
    for name, frame in HELPER_FRAMES.items():
        assert depth(name.removeprefix("__builtin_")) == frame, name


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


PLACEHOLDER = 'node: { title: "__indirect_call" label: "Indirect Call Placeholder" shape : ellipse }'


def test_an_indirect_call_bounded_by_its_named_targets(tmp_path):
    # As flash_g4.c's pour_flash_write_page calls its stall hook: a pointer whose only value the caller knows.
    # Unbounded, the call may reach tick (nobody calls it directly), which reaches write_page again.
    g = graph(tmp_path, PLACEHOLDER, node("run", 32), node("tick", 400), node("save", 40), node("write_page", 24),
              node("stall", 8), node("hook", 96), edge("run", "save"), edge("tick", "save"),
              edge("save", "write_page"), edge("write_page", "__indirect_call"))
    r = run(str(g), "--root", "run")
    assert r.returncode == 2 and "recursion through" in r.stderr and not r.stdout
    r = run(str(g), "--root", "run", "--indirect", "write_page=stall")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "run 104 run>save>write_page>stall"
    # several targets: the deepest counts
    r = run(str(g), "--root", "run", "--indirect", "write_page=stall,hook")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "run 192 run>save>write_page>hook"
    # only the named caller is bounded: another indirect call still takes the worst uncalled function
    g2 = graph(tmp_path, PLACEHOLDER, node("run", 32), node("write_page", 24), node("stall", 8), node("hook", 96),
               node("other", 16), edge("run", "write_page"), edge("run", "other"),
               edge("write_page", "__indirect_call"), edge("other", "__indirect_call"))
    r = run(str(g2), "--root", "run", "--indirect", "write_page=stall")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "run 144 run>other>hook"


def test_an_indirect_bound_naming_what_is_not_there_is_refused(tmp_path):
    g = graph(tmp_path, PLACEHOLDER, node("run", 32), node("write_page", 24), node("stall", 8), node("plain", 8),
              edge("run", "write_page"), edge("run", "plain"), edge("write_page", "__indirect_call"))
    for spec, says in (("write_page=flash_stall", "target flash_stall of write_page is not in the call graph"),
                       ("write_pages=stall", "function write_pages is not in the call graph"),
                       ("plain=stall", "plain makes no indirect call"),
                       ("write_page", "expected CALLER=TARGET"), ("write_page=stall,", "expected CALLER=TARGET"),
                       ("=stall", "expected CALLER=TARGET")):
        r = run(str(g), "--root", "run", "--indirect", spec)
        assert r.returncode == 2, spec
        assert says in r.stderr and len(r.stderr.strip().splitlines()) == 1 and not r.stdout, (spec, r.stderr)
        assert "Traceback" not in r.stderr
