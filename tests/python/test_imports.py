# SPDX-License-Identifier: MIT
"""The pour package's import graph has no cycle, lazy (function-level) imports included; its subpackages
import each other only in the direction pour/__init__.py's table allows; and one module, pour.paths, finds
the build tree."""
import ast
import re
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[2] / "tools"
PKG = TOOLS / "pour"


def module_name(path: Path, root: Path = TOOLS) -> str:
    """tools/pour/sim/envs.py -> pour.sim.envs; a package's __init__.py -> the package."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, package: str = "pour") -> set[str]:
    """What path imports from pour anywhere in its body, as dotted names (pour.x.y; for `from A import n`,
    both A.n and A, the caller keeps what exists). package: the package path lives in, for relative imports."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name == "pour" or a.name.startswith("pour.")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: from . import x / from .x import y
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod == "pour" or mod.startswith("pour."):
                out.add(mod)
                out |= {f"{mod}.{a.name}" for a in node.names}
    return out


def import_graph() -> dict[str, set[str]]:
    """Every module of the package -> the package's modules it imports (a name that is a module, else the
    deepest package or module that holds it)."""
    files = sorted(PKG.rglob("*.py"))
    mods = {module_name(p) for p in files}
    graph = {}
    for p in files:
        me = module_name(p)
        pkg = me if p.name == "__init__.py" else me.rpartition(".")[0]
        deps = set()
        for name in _imports(p, pkg):
            while name not in mods and "." in name:
                name = name.rpartition(".")[0]
            if name in mods and name not in (me, "pour"):
                deps.add(name)
        graph[me] = deps
    return graph


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
    g = {f"pour.{p.stem}": _imports(p) for p in tmp_path.glob("*.py")}
    assert find_cycle(g) == ["pour.a", "pour.b", "pour.c", "pour.a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def _build_tree_lookups(path: Path) -> list[str]:
    """Where path reads $POUR_BUILD_DIR or $POUR_SIM_LIB, or locates itself through __file__."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Name) and node.id == "__file__":
            found.append(f"{module_name(path, path.parents[1])}:{node.lineno}: __file__")
        key = None
        if isinstance(node, ast.Subscript) and ast.unparse(node.value) == "os.environ":
            key = node.slice
        elif isinstance(node, ast.Call) and ast.unparse(node.func) in ("os.environ.get", "os.getenv") and node.args:
            key = node.args[0]
        if isinstance(key, ast.Constant) and key.value in ("POUR_BUILD_DIR", "POUR_SIM_LIB"):
            found.append(f"{module_name(path, path.parents[1])}:{node.lineno}: ${key.value}")
    return found


def test_only_paths_looks_for_the_build_tree(tmp_path):
    """$POUR_BUILD_DIR, $POUR_SIM_LIB and the checkout's own location (__file__) are read in pour.paths alone."""
    offenders = [f for p in sorted(PKG.rglob("*.py")) if p != PKG / "paths.py" for f in _build_tree_lookups(p)]
    assert not offenders, "\n".join(offenders)
    (tmp_path / "x.py").write_text('import os\nd = os.environ.get("POUR_BUILD_DIR")\nr = __file__\n')
    assert len(_build_tree_lookups(tmp_path / "x.py")) == 2


# Which subpackage may import which (the shared top-level modules, pour.paths, pour.atomic and
# pour.libpoursim and pour.records, may be imported by any and import none). The same table is in pour/__init__.py.
ALLOWED: dict[str, set[str]] = {
    "core": set(),
    "policy": {"core"},
    "sim": {"policy", "core"},
    "train": {"sim", "policy", "sysid"},
    "eval": {"train", "sim", "policy", "sysid"},
    "lcm": {"eval", "sim"},
    "can": set(),
    "bench": {"can", "policy"},
    "examples": {"train", "sim", "policy"},
    "sysid": {"bench", "sim"},
}


def layer(module: str) -> str:
    """pour.sim.envs -> sim; a top-level module (pour.paths) -> "shared"."""
    parts = module.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and parts[1] in ALLOWED) else "shared"


def forbidden_imports(graph: dict[str, set[str]], allowed: dict[str, set[str]]) -> list[str]:
    """The edges a -> b of graph that cross from one subpackage into one its row does not name."""
    bad = []
    for a, deps in sorted(graph.items()):
        la = layer(a)
        for b in sorted(deps):
            lb = layer(b)
            if lb == la or (lb == "shared" and la != "shared") or (la != "shared" and lb in allowed[la]):
                continue
            bad.append(f"{a} -> {b} ({la} may import {sorted(allowed.get(la, ())) or 'no subpackage'})")
    return bad


def test_subpackages_import_only_in_the_allowed_direction():
    assert set(ALLOWED) == {p.name for p in PKG.iterdir() if (p / "__init__.py").is_file()}
    bad = forbidden_imports(import_graph(), ALLOWED)
    assert not bad, "\n".join(bad)


def test_the_package_docstring_states_the_same_table():
    doc = ast.get_docstring(ast.parse((PKG / "__init__.py").read_text(encoding="utf-8")))
    rows = dict(re.findall(r"^ {4}pour\.(\w+) {2,}(-|[\w, ]+)$", doc, re.M))
    assert {k: set() if v == "-" else {x.strip() for x in v.split(",")} for k, v in rows.items()} == ALLOWED


def test_the_direction_check_finds_a_wrong_way_import():
    graph = {"pour.sim.envs": {"pour.train.reinforce", "pour.policy.linear", "pour.paths"},
             "pour.paths": {"pour.sim.poursim"}, "pour.core": {"pour.libpoursim"}}
    assert forbidden_imports(graph, ALLOWED) == [
        "pour.paths -> pour.sim.poursim (shared may import no subpackage)",
        "pour.sim.envs -> pour.train.reinforce (sim may import ['core', 'policy'])"]
