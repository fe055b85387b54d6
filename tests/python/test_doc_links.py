# SPDX-License-Identifier: MIT
"""Every relative link of README.md and docs/ (notes included) names a file that exists, and a link to a
heading of a markdown file names a heading it has (GitHub's anchors: lower case, punctuation dropped, spaces
to hyphens). README.md keeps to 150 lines, none over 120 characters outside code blocks."""
import re
from pathlib import Path

import pytest

from conftest import SOURCE_DIR

PAGES = [SOURCE_DIR / "README.md", *sorted((SOURCE_DIR / "docs").rglob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def anchors(md: Path) -> set[str]:
    out, inside = set(), False
    for line in md.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            inside = not inside
        elif not inside and line.startswith("#"):
            title = line.lstrip("#").strip().lower()
            out.add(re.sub(r"\s", "-", re.sub(r"[^\w\s-]", "", title)))
    return out


def links(md: Path) -> list[str]:
    text = re.sub(r"```.*?```", "", md.read_text(encoding="utf-8"), flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    return [t for t in LINK.findall(text) if not re.match(r"[a-z]+:", t)]


@pytest.mark.parametrize("md", PAGES, ids=lambda p: str(p.relative_to(SOURCE_DIR)))
def test_every_relative_link_resolves(md):
    bad = []
    for target in links(md):
        path, _, anchor = target.partition("#")
        dest = (md.parent / path).resolve() if path else md
        if not dest.exists():
            bad.append(target)
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            bad.append(target)
    assert not bad, f"{md.relative_to(SOURCE_DIR)}: broken links {bad}"


def test_the_link_check_can_disagree(tmp_path):
    page = tmp_path / "a.md"
    page.write_text("# A b\n[x](missing.md) [y](a.md#a-b) [z](a.md#no-such)\n")
    assert links(page) == ["missing.md", "a.md#a-b", "a.md#no-such"] and "a-b" in anchors(page)


def test_readme_is_short_and_narrow():
    lines = (SOURCE_DIR / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150, len(lines)
    inside, wide = False, []
    for n, line in enumerate(lines, 1):
        if line.startswith("```"):
            inside = not inside
        elif not inside and len(line) > 120:
            wide.append(n)
    assert not wide, f"README.md lines over 120 characters: {wide}"
