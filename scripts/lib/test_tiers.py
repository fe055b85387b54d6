#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks a configured preset's two tiers: every label that a test of `ctest --preset PRESET-all` carries
is carried by at least one test of `ctest --preset PRESET` (the quick tier, which leaves out the tests
labelled `slow`), so no area is tested only by ./scripts/test.sh --all.

    test_tiers.py PRESET     (run from the checkout, after the preset is configured)

Prints one line per preset: the test counts of both tiers; exit 1 naming each label the quick tier lacks,
2 on bad usage or when ctest cannot list the tests.
"""
from __future__ import annotations

import json
import subprocess
import sys

SLOW = "slow"


def labels_of(preset: str) -> list[set[str]]:
    """The label set of each test that `ctest --preset preset` would run."""
    res = subprocess.run(["ctest", "--preset", preset, "--show-only=json-v1"], capture_output=True, text=True)
    if res.returncode != 0:
        first = (res.stderr.strip().splitlines() or ["no message"])[0]
        raise RuntimeError(f"ctest --preset {preset} cannot list its tests: {first[:200]}")
    tests = json.loads(res.stdout).get("tests", [])
    out = []
    for test in tests:
        props = {p["name"]: p["value"] for p in test.get("properties", [])}
        out.append(set(props.get("LABELS", [])))
    return out


def main(argv: list[str]) -> int:
    if argv[:1] in (["-h"], ["--help"]):
        print(__doc__.strip())
        return 0
    if len(argv) != 1:
        print("test_tiers: usage: test_tiers.py PRESET", file=sys.stderr)
        return 2
    preset = argv[0]
    try:
        every = labels_of(f"{preset}-all")
        quick = labels_of(preset)
    except (RuntimeError, json.JSONDecodeError) as exc:
        print(f"test_tiers: {exc}", file=sys.stderr)
        return 2
    if any(SLOW in labels for labels in quick):
        print(f"test_tiers: {preset}: the quick tier runs a test labelled '{SLOW}'", file=sys.stderr)
        return 1
    wanted = set().union(*every) - {SLOW} if every else set()
    have = set().union(*quick) if quick else set()
    missing = sorted(wanted - have)
    n_slow = sum(SLOW in labels for labels in every)
    print(f"tiers: {preset}: {len(quick)} quick tests, {n_slow} slow ones more with --all")
    if missing:
        print(f"test_tiers: {preset}: label(s) {', '.join(missing)} have tests only in the slow tier "
              "(--all); keep at least one of each in the quick tier", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
