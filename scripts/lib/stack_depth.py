#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Worst-case stack depth of functions in a linked image, from GCC's call graph (-fcallgraph-info=su).

    stack_depth.py GRAPH.ci [GRAPH.ci ...] --root NAME [--root NAME ...] [--entry NAME ...]

The cortex-m4 images are linked with -flto, so the per-object .su files of -fstack-usage do not exist and
functions are inlined across files; the link writes one .ci file per ltrans unit, whose nodes carry each
function's frame as compiled into the image and whose edges are its calls. For each root (a name as in
the source; GCC's clone suffixes such as .constprop or .isra are ignored) this prints

    NAME BYTES PATH [uncounted: HELPERS]

BYTES being the deepest chain of frames from NAME (PATH, joined by '>'). An indirect call may reach any
function that no one calls directly, other than the roots and the --entry names (the vector table's
handlers): the worst of those is taken. Library helpers (memset, __aeabi_ldivmod, ...) come with no frame
size; those reachable from the root are listed as uncounted. Recursion, a dynamic frame or a root that is not in the
graph is an error (exit status 2).
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
                    self.frame[title] = None
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
            self.name[dst], self.frame[dst] = name, max(frames) if frames else None
            if frames:  # the calls of the function by that name (another unit's definition)
                self.calls[dst] = set().union(*(self.calls.get(t, set()) for t in self.frame
                                               if self.name[t] == name and t != dst))

    def titles(self, name: str) -> list[str]:
        return [t for t, n in self.name.items() if n == name and t != INDIRECT]

    def depths(self, roots: list[str], entries: list[str]) -> dict[str, tuple[int, list[str], set[str]]]:
        self.resolve()
        starts = {r: self.titles(r) for r in roots}
        for r, ts in starts.items():
            if not ts:
                raise GraphError(f"function {r} is not in the call graph (inlined into its caller, or absent)")
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
                own, targets, label = self.frame.get(t), sorted(self.calls.get(t, ())), [self.name.get(t, t)]
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
    a = p.parse_args(argv)
    g = Graph()
    try:
        for path in a.graphs:
            g.read(path)
        depths = g.depths(a.root, a.entry)
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
