# SPDX-License-Identifier: MIT
"""The pour package's import graph has no cycle, lazy (function-level) imports included, and one module,
pour.paths, finds the build tree."""
import ast
import re
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[2] / "tools" / "pour"


def _imports(path: Path) -> set[str]:
    """The pour modules that path imports anywhere in its body (pour.x, from pour import x, from pour.x ...)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("pour."):
                    out.add(a.name.split(".")[1])
        elif isinstance(node, ast.ImportFrom):
            mod = node.module or ""
            if node.level:  # relative: from . import x / from .x import y
                out |= {mod.split(".")[0]} if mod else {a.name for a in node.names}
            elif mod == "pour":
                out |= {a.name for a in node.names}
            elif mod.startswith("pour."):
                out.add(mod.split(".")[1])
    return out


def import_graph() -> dict[str, set[str]]:
    mods = {p.stem for p in PKG.glob("*.py")}
    return {p.stem: (_imports(p) & mods) - {p.stem} for p in sorted(PKG.glob("*.py"))}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle as [a, b, ..., a], or None (depth-first search, three colours)."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph.get(m, ())):
            if state.get(n) == 1:
                return stack[stack.index(n):] + [n]
            if n not in state:
                c = visit(n)
                if c:
                    return c
        stack.pop()
        state[m] = 2
        return None

    for m in sorted(graph):
        if m not in state:
            c = visit(m)
            if c:
                return c
    return None


def test_package_has_no_import_cycle():
    cycle = find_cycle(import_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_cycle_finder_finds_a_lazy_cycle(tmp_path):
    (tmp_path / "a.py").write_text("from pour import b\n")
    (tmp_path / "b.py").write_text("def f():\n    from pour import c\n")
    (tmp_path / "c.py").write_text("import pour.a\n")
    g = {p.stem: _imports(p) for p in tmp_path.glob("*.py")}
    assert find_cycle(g) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def _build_tree_lookups(path: Path) -> list[str]:
    """Where path reads $POUR_BUILD_DIR or $POUR_SIM_LIB, or locates itself through __file__."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Name) and node.id == "__file__":
            found.append(f"{path.name}:{node.lineno}: __file__")
        key = None
        if isinstance(node, ast.Subscript) and ast.unparse(node.value) == "os.environ":
            key = node.slice
        elif isinstance(node, ast.Call) and ast.unparse(node.func) in ("os.environ.get", "os.getenv") and node.args:
            key = node.args[0]
        if isinstance(key, ast.Constant) and key.value in ("POUR_BUILD_DIR", "POUR_SIM_LIB"):
            found.append(f"{path.name}:{node.lineno}: ${key.value}")
    return found


def test_only_paths_looks_for_the_build_tree(tmp_path):
    """$POUR_BUILD_DIR, $POUR_SIM_LIB and the checkout's own location (__file__) are read in pour.paths alone."""
    offenders = [f for p in sorted(PKG.glob("*.py")) if p.name != "paths.py" for f in _build_tree_lookups(p)]
    assert not offenders, "\n".join(offenders)
    (tmp_path / "x.py").write_text('import os\nd = os.environ.get("POUR_BUILD_DIR")\nr = __file__\n')
    assert len(_build_tree_lookups(tmp_path / "x.py")) == 2
