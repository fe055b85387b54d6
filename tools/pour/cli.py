# SPDX-License-Identifier: MIT
"""What every pour-* program shares on its command line: --version, and progress with the time left on
stderr (tqdm), which --quiet turns off. Imports no subpackage."""
from __future__ import annotations

import argparse
import sys
from importlib import metadata
from typing import Iterable, TypeVar

from tqdm import tqdm

T = TypeVar("T")


def version() -> str:
    """The installed pour-tools version."""
    try:
        return metadata.version("pour-tools")
    except metadata.PackageNotFoundError:
        return "unknown (pour-tools is not installed)"


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser with --version (prints `PROG VERSION`, exit 0)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.add_argument("--version", action="version", version=f"%(prog)s {version()}")


def progress(items: Iterable[T], total: int | None = None, desc: str | None = None, quiet: bool = False,
             unit: str = "it") -> Iterable[T]:
    """items, with a progress bar on stderr (done, rate and time left) unless quiet."""
    return tqdm(items, total=total, desc=desc, unit=unit, disable=quiet, file=sys.stderr, dynamic_ncols=True)


def bar(total: int, desc: str | None = None, quiet: bool = False, unit: str = "it") -> tqdm:
    """A progress bar on stderr for work counted by hand (bar.update(n)); a context manager."""
    return tqdm(total=total, desc=desc, unit=unit, disable=quiet, file=sys.stderr, dynamic_ncols=True)


def time_left(done: int, total: int, elapsed_s: float) -> str:
    """The time left at this rate, as tqdm writes it (m:ss or h:mm:ss), for progress printed as log lines."""
    if done <= 0:
        return "?"
    return tqdm.format_interval(max(0.0, elapsed_s / done * (total - done)))
