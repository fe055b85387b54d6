#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks one local .crate file against its pinned sha256 and unpacks it under a folder.

    unpack_crate.py NAME VERSION SHA256 CRATE_FILE DEST

scripts/setup.sh runs it on the .crate files cargo fetched into its cache. A .crate file is a gzipped tar
whose every member sits under NAME-VERSION/. The file is copied to a temporary name inside DEST while its
sha256 is computed, compared with the pin, and only then unpacked from that copy, into a second temporary
folder that is renamed to DEST/NAME-VERSION once complete. A hash that differs from the pin is refused by
name, a member that would land outside NAME-VERSION/ (an absolute path, "..", a link, a device) too; in
either case nothing is left in DEST and an older DEST/NAME-VERSION is kept. On success the absolute path of
the unpacked crate is the one line on stdout. Run with Debian's python3 before the venv exists: standard
library only.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tarfile
import tempfile
from pathlib import Path, PurePosixPath

NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$")
VERSION_RE = re.compile(r"^[0-9]+\.[0-9]+\.[0-9]+(?:[-+][0-9A-Za-z.+-]+)?$")
SHA_RE = re.compile(r"^[0-9a-f]{64}$")
USAGE = "usage: unpack_crate.py NAME VERSION SHA256 CRATE_FILE DEST"


class UnpackError(Exception):
    """An expected failure: one line for the user, exit status 1."""


def _copy(src: Path, out) -> str:
    """Copies the file src into the open binary file out; returns the hex sha256 of what was written."""
    digest = hashlib.sha256()
    try:
        with open(src, "rb") as inp:
            while True:
                block = inp.read(1 << 16)
                if not block:
                    break
                digest.update(block)
                out.write(block)
    except OSError as exc:
        raise UnpackError(f"cannot read {src}: {exc.strerror or exc}") from None
    return digest.hexdigest()


def _check_members(tar: tarfile.TarFile, top: str) -> None:
    """Refuses any member that is not a plain file or folder under top/."""
    for member in tar.getmembers():
        path = PurePosixPath(member.name)
        if path.is_absolute() or ".." in path.parts or not path.parts or path.parts[0] != top:
            raise UnpackError(f"member '{member.name}' lies outside {top}/")
        if not (member.isfile() or member.isdir()):
            raise UnpackError(f"member '{member.name}' is not a plain file or folder")


def unpack(name: str, version: str, sha256: str, crate: Path, dest: Path) -> Path:
    """Verifies the file crate and unpacks NAME-VERSION under dest; returns the unpacked folder's absolute
    path. An existing dest/NAME-VERSION is replaced only after the new copy is complete."""
    if not NAME_RE.match(name):
        raise UnpackError(f"'{name}' is not a crate name")
    if not VERSION_RE.match(version):
        raise UnpackError(f"'{version}' is not a crate version")
    if not SHA_RE.match(sha256):
        raise UnpackError(f"'{sha256}' is not a sha256 (64 lower-case hex digits)")
    if not crate.is_file():
        raise UnpackError(f"no file {crate}")
    top = f"{name}-{version}"
    dest = dest.resolve()
    dest.mkdir(parents=True, exist_ok=True)
    fd, part_name = tempfile.mkstemp(prefix=f".{top}.", suffix=".crate.part", dir=dest)
    part = Path(part_name)
    tmp: Path | None = None
    try:
        with os.fdopen(fd, "wb") as out:
            got = _copy(crate, out)
        if got != sha256:
            raise UnpackError(f"{name} {version}: sha256 {got} of {crate.name} differs from the pinned"
                              f" {sha256}; refused")
        tmp = Path(tempfile.mkdtemp(prefix=f".{top}.", suffix=".unpack", dir=dest))
        try:
            with tarfile.open(part, "r:gz") as tar:
                _check_members(tar, top)
                # No owner, mode or time from the archive: files and folders as the umask makes them.
                extra = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
                for member in tar.getmembers():
                    tar.extract(member, tmp, set_attrs=False, **extra)
        except (tarfile.TarError, EOFError, OSError) as exc:
            raise UnpackError(f"{name} {version}: not a readable .crate file ({exc})") from None
        if not (tmp / top).is_dir():
            raise UnpackError(f"{name} {version}: the .crate file holds no {top}/ folder")
        final = dest / top
        if final.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{top}.", suffix=".old", dir=dest))
            final.rename(old / top)
            (tmp / top).rename(final)
            shutil.rmtree(old)
        else:
            (tmp / top).rename(final)
        return final
    finally:
        part.unlink(missing_ok=True)
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)


def main(argv: list[str]) -> int:
    if argv and argv[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0
    if len(argv) != 5:
        print(f"unpack_crate: {USAGE}", file=sys.stderr)
        return 2
    name, version, sha256, crate, dest = argv
    try:
        path = unpack(name, version, sha256, Path(crate), Path(dest))
    except UnpackError as exc:
        print(f"unpack_crate: {exc}", file=sys.stderr)
        return 1
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
