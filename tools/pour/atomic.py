# SPDX-License-Identifier: MIT
"""Atomic outputs: a file is written to a temporary beside its target, synced, then renamed over it.

A reader sees the old file or the new one, never a partial one: a full disk, an exception or Ctrl-C
while writing leaves the previous file as it was and removes the temporary.
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Iterator, Union

PathLike = Union[str, os.PathLike]


def check_output_path(path: PathLike, what: str = "output") -> Path:
    """The path, if a file can be created there: not empty, not a directory, its folder exists.
    Raises ValueError with a one-line reason otherwise (to be checked before any work starts)."""
    if str(path) == "":
        raise ValueError(f"{what}: the path is empty")
    p = Path(path)
    if p.is_dir() or str(path).endswith(os.sep):
        raise ValueError(f"{what}: {p} is a directory, not a file name")
    parent = p.parent
    if not parent.is_dir():
        raise ValueError(f"{what}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise ValueError(f"{what}: folder {parent} is not writable")
    return p


def _fsync_dir(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """Yields a temporary path beside path (same suffix, so writers that go by the suffix still work); when
    the block ends without an exception, syncs it and renames it to path. On an exception, removes it."""
    target = Path(path)
    fd, tmp_name = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=f".tmp{target.suffix}")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    _fsync_dir(target.parent)


def write_atomic(path: PathLike, data: bytes | str) -> None:
    """Writes data (str as UTF-8) to path atomically."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(raw)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
