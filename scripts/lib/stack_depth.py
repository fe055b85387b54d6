#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Worst-case stack depth of functions in a linked image, from GCC's call graph (-fcallgraph-info=su).

    stack_depth.py GRAPH.ci [GRAPH.ci ...] --root NAME [--root NAME ...] [--entry NAME ...]
                   [--indirect CALLER=TARGET[,TARGET ...] ...]

The cortex-m4 images are linked with -flto, so the per-object .su files of -fstack-usage do not exist and
functions are inlined across files; the link writes one .ci file per ltrans unit, whose nodes carry each
function's frame as compiled into the image and whose edges are its calls. For each root (a name as in
the source; GCC's clone suffixes such as .constprop or .isra are ignored) this prints

    NAME BYTES PATH [uncounted: HELPERS]

BYTES being the deepest chain of frames from NAME (PATH, joined by '>'). An indirect call may reach any
function that no one calls directly, other than the roots and the --entry names (the vector table's
handlers): the worst of those is taken, unless --indirect names what CALLER's indirect calls may reach (a
function pointer with known values, e.g. a hook set once at start-up): then those targets alone, each of
which must be in the graph. Library helpers (memset, __aeabi_ldivmod, ...) come with no frame
size: those in HELPER_FRAMES are counted with the frame read from the library's disassembly, any other one
reachable from the root is listed as uncounted. Recursion, a dynamic frame or a root that is not in the graph is
an error (exit status 2), and so is an --indirect whose caller or target is not in the graph or whose caller
makes no indirect call.
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

NODE = re.compile(r'^node: \{ title: "(?P<title>[^"]+)" label: "(?P<label>[^"]*)"')
EDGE = re.compile(r'^edge: \{ sourcename: "(?P<src>[^"]+)" targetname: "(?P<dst>[^"]+)"')
FRAME = re.compile(r"\\n(\d+) bytes \((static|dynamic[^)]*)\)$")
INDIRECT = "__indirect_call"

# The deepest stack [B] of each library helper the cortex-m4 image calls, its own frame and its callees', read
# from `arm-none-eabi-objdump -d` of the multilib it links (gcc-arm-none-eabi 12.2, thumb/v7e-m/nofp; the
# image's own disassembly shows the same code). tests/python/test_stack_depth.py reads them again from the
# libraries, so a toolchain whose helpers grow fails there.
HELPER_FRAMES = {
    # libgcc.a(_aeabi_ldivmod.o), (_aeabi_uldivmod.o): `strd ip, lr, [sp, #-16]!` (16), then `bl __udivmoddi4`,
    # libgcc.a(_udivmoddi4.o): `stmdb sp!, {r4-r10, lr}` (32), which calls nothing.
    "__aeabi_ldivmod": 16 + 32,
    "__aeabi_uldivmod": 16 + 32,
    # libc_nano.a(lib_a-memcpy.o): no push and no call, it works in r0-r3 and ip.
    "__builtin_memcpy": 0,
    # libc_nano.a(lib_a-memset.o): `push {r4, r5, lr}`, no call.
    "__builtin_memset": 12,
    # The same two functions as a call by their own name (a node titled "memset" labelled with string.h's
    # declaration, beside the built-in's: the graph keeps one of them).
    "memcpy": 0,
    "memset": 12,
}


class GraphError(Exception):
    pass


class Graph:
    def __init__(self) -> None:
        self.name: dict[str, str] = {}  # title -> source name
        self.frame: dict[str, int | None] = {}  # title -> bytes, None for a helper without a size
        self.calls: dict[str, set[str]] = {}

    def read(self, path: Path) -> None:
        try:
            text = path.read_text()
        except OSError as e:
            raise GraphError(f"cannot read {path}: {e.strerror}") from e
        if not text.startswith("graph: {"):
            raise GraphError(f"{path}: not a GCC call graph (-fcallgraph-info)")
        for line in text.splitlines():
            if m := NODE.match(line):
                title, label = m["title"], m["label"]
                self.name[title] = label.split("\\n", 1)[0].split(".", 1)[0]
                f = FRAME.search(label)
                if f is None:
                    self.frame[title] = HELPER_FRAMES.get(self.name[title])
                elif f[2] != "static":
                    raise GraphError(f"{path}: {self.name[title]} has a dynamic stack frame ({f[2]})")
                else:
                    self.frame[title] = int(f[1])
                self.calls.setdefault(title, set())
            elif m := EDGE.match(line):
                self.calls.setdefault(m["src"], set()).add(m["dst"])

    def resolve(self) -> None:
        """A call into another unit, or into a copy of a static inline function that GCC names but does not
        list, is known by its name only: it gets the largest frame of that name (a helper if none)."""
        for dst in {d for ds in self.calls.values() for d in ds} - set(self.name):
            name = dst.rsplit(":", 1)[-1].split(".", 1)[0]
            frames = [f for t, f in self.frame.items() if self.name[t] == name and f is not None]
            self.name[dst], self.frame[dst] = name, max(frames) if frames else HELPER_FRAMES.get(name)
            if frames:  # the calls of the function by that name (another unit's definition)
                self.calls[dst] = set().union(*(self.calls.get(t, set()) for t in self.frame
                                               if self.name[t] == name and t != dst))

    def titles(self, name: str) -> list[str]:
        return [t for t, n in self.name.items() if n == name and t != INDIRECT]

    def depths(self, roots: list[str], entries: list[str], indirect: dict[str, list[str]] | None = None
               ) -> dict[str, tuple[int, list[str], set[str]]]:
        self.resolve()
        starts = {r: self.titles(r) for r in roots}
        for r, ts in starts.items():
            if not ts:
                raise GraphError(f"function {r} is not in the call graph (inlined into its caller, or absent)")
        bound: dict[str, list[str]] = {}  # caller's title -> the titles its indirect calls may reach
        for caller, targets in (indirect or {}).items():
            callers = self.titles(caller)
            if not callers:
                raise GraphError(f"--indirect: function {caller} is not in the call graph (inlined, or absent)")
            with_indirect = [t for t in callers if INDIRECT in self.calls.get(t, ())]
            if not with_indirect:
                raise GraphError(f"--indirect: {caller} makes no indirect call in the call graph")
            titles = []
            for target in targets:
                ts = [t for t in self.titles(target) if self.frame.get(t) is not None]
                if not ts:
                    raise GraphError(f"--indirect: target {target} of {caller} is not in the call graph "
                                     "(inlined, or absent)")
                titles += ts
            for t in with_indirect:
                bound[t] = titles
        called = {self.name[d] for ds in self.calls.values() for d in ds}
        excluded = set(roots) | set(entries)
        orphans = [t for t in self.frame
                   if self.name[t] not in called | excluded and self.frame[t] is not None]
        memo: dict[str, tuple[int, list[str], set[str]]] = {}
        active: set[str] = set()

        def visit(t: str) -> tuple[int, list[str], set[str]]:
            if t in memo:
                return memo[t]
            if t in active:
                raise GraphError(f"recursion through {self.name.get(t, t)} (or an indirect call that may reach "
                                 "its caller): no bound on the stack")
            active.add(t)
            if t == INDIRECT:
                own, targets, label = 0, orphans, []
            else:
                own, label = self.frame.get(t), [self.name.get(t, t)]
                calls = self.calls.get(t, set())
                if t in bound:
                    calls = (calls - {INDIRECT}) | set(bound[t])
                targets = sorted(calls)
            depth, path, helpers = 0, [], set() if own is not None else {self.name.get(t, t)}
            for d in targets:
                sub = visit(d)
                helpers |= sub[2]
                if sub[0] > depth or not path:
                    depth, path = sub[0], sub[1]
            active.discard(t)
            memo[t] = ((own or 0) + depth, label + path, helpers)
            return memo[t]

        out = {}
        for r, ts in starts.items():
            out[r] = max((visit(t) for t in ts), key=lambda v: v[0])
        return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0])
    p.add_argument("graphs", nargs="+", type=Path, help="the .ci files of one image's link")
    p.add_argument("--root", action="append", required=True, help="a function whose deepest chain to print")
    p.add_argument("--entry", action="append", default=[], help="a vector-table handler (never an indirect target)")
    p.add_argument("--indirect", action="append", default=[], metavar="CALLER=TARGET[,TARGET...]",
                   help="the only functions CALLER's indirect calls may reach (each must be in the graph)")
    a = p.parse_args(argv)
    indirect: dict[str, list[str]] = {}
    for spec in a.indirect:
        caller, _, targets = spec.partition("=")
        names = [n for n in targets.split(",") if n]
        if not caller or not names or len(names) != len(targets.split(",")):
            print(f"stack_depth: error: --indirect {spec!r}: expected CALLER=TARGET[,TARGET...]", file=sys.stderr)
            return 2
        indirect.setdefault(caller, []).extend(names)
    g = Graph()
    try:
        for path in a.graphs:
            g.read(path)
        depths = g.depths(a.root, a.entry, indirect)
    except GraphError as e:
        print(f"stack_depth: error: {e}", file=sys.stderr)
        return 2
    for r in a.root:
        n, path, helpers = depths[r]
        extra = f" uncounted: {','.join(sorted(helpers))}" if helpers else ""
        print(f"{r} {n} {'>'.join(path)}{extra}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
