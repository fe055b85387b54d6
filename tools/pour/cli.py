# SPDX-License-Identifier: MIT
"""What every pour-* program shares on its command line: --version, and progress with the time left on
stderr (tqdm), which --quiet turns off. Imports no subpackage."""
from __future__ import annotations

import argparse
import importlib
import os
import sys
from importlib import metadata
from types import ModuleType
from typing import Iterable, TypeVar

from tqdm import tqdm

T = TypeVar("T")


def version() -> str:
    """The installed pour-tools version."""
    try:
        return metadata.version("pour-tools")
    except metadata.PackageNotFoundError:
        return "unknown (pour-tools is not installed)"


class MissingExtra(SystemExit):
    """An optional extra is not installed: exits 1 with one line naming the extra to install."""


def require(module: str, extra: str) -> ModuleType:
    """module, imported where it is used; MissingExtra (one line: the program, the module, the extra) when it is
    not installed. An ImportError from inside an installed module is not caught."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if exc.name is None or exc.name.split(".")[0] != module.split(".")[0]:
            raise
        prog = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "pour"
        raise MissingExtra(f"{prog}: {module} is not installed: it comes with the {extra} extra "
                           f"(pip install './tools[{extra}]')") from None


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
