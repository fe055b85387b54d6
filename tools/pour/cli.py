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
