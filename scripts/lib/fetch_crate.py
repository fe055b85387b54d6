#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Fetches one pinned .crate file, checks its sha256 and unpacks it under a folder, with no cargo.

    fetch_crate.py NAME VERSION SHA256 DEST [--base URL]

A .crate file is a gzipped tar whose every member sits under NAME-VERSION/. The file is downloaded to a
temporary name inside DEST, its sha256 compared with the pin, and only then unpacked, into a second
temporary folder that is renamed to DEST/NAME-VERSION once complete. A hash that differs from the pin is
refused by name, a member that would land outside NAME-VERSION/ (an absolute path, "..", a link, a device)
too; in either case nothing is left in DEST. On success the absolute path of the unpacked crate is the one
line on stdout. Run by scripts/setup.sh with Debian's python3 before the venv exists: standard library only.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tarfile
import tempfile
import urllib.error
import urllib.request
from pathlib import Path, PurePosixPath

# The crate registry's static download endpoint: BASE/NAME/NAME-VERSION.crate.
DEFAULT_BASE = "https://static.crates.io/crates"
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$")
VERSION_RE = re.compile(r"^[0-9]+\.[0-9]+\.[0-9]+(?:[-+][0-9A-Za-z.+-]+)?$")
SHA_RE = re.compile(r"^[0-9a-f]{64}$")


class FetchError(Exception):
    """An expected failure: one line for the user, exit status 1."""


def _download(url: str, out) -> str:
    """Streams url into the open binary file out; returns the hex sha256 of what was written."""
    digest = hashlib.sha256()
    try:
        with urllib.request.urlopen(url, timeout=120) as resp:
            while True:
                block = resp.read(1 << 16)
                if not block:
                    break
                digest.update(block)
                out.write(block)
    except (urllib.error.URLError, OSError, ValueError) as exc:
        reason = getattr(exc, "reason", None) or exc
        raise FetchError(f"cannot download {url}: {reason}") from None
    return digest.hexdigest()


def _check_members(tar: tarfile.TarFile, top: str) -> None:
    """Refuses any member that is not a plain file or folder under top/."""
    for member in tar.getmembers():
        path = PurePosixPath(member.name)
        if path.is_absolute() or ".." in path.parts or not path.parts or path.parts[0] != top:
            raise FetchError(f"member '{member.name}' lies outside {top}/")
        if not (member.isfile() or member.isdir()):
            raise FetchError(f"member '{member.name}' is not a plain file or folder")


def fetch(name: str, version: str, sha256: str, dest: Path, base: str = DEFAULT_BASE) -> Path:
    """Fetches, verifies and unpacks NAME-VERSION under dest; returns the unpacked folder's absolute path.
    An existing dest/NAME-VERSION is replaced only after the new copy is complete."""
    if not NAME_RE.match(name):
        raise FetchError(f"'{name}' is not a crate name")
    if not VERSION_RE.match(version):
        raise FetchError(f"'{version}' is not a crate version")
    if not SHA_RE.match(sha256):
        raise FetchError(f"'{sha256}' is not a sha256 (64 lower-case hex digits)")
    top = f"{name}-{version}"
    dest = dest.resolve()
    dest.mkdir(parents=True, exist_ok=True)
    url = f"{base.rstrip('/')}/{name}/{top}.crate"
    fd, part_name = tempfile.mkstemp(prefix=f".{top}.", suffix=".crate.part", dir=dest)
    part = Path(part_name)
    unpack: Path | None = None
    try:
        with os.fdopen(fd, "wb") as out:
            got = _download(url, out)
        if got != sha256:
            raise FetchError(f"{name} {version}: sha256 {got} differs from the pinned {sha256}; refused")
        unpack = Path(tempfile.mkdtemp(prefix=f".{top}.", suffix=".unpack", dir=dest))
        try:
            with tarfile.open(part, "r:gz") as tar:
                _check_members(tar, top)
                # No owner, mode or time from the archive: files and folders as the umask makes them.
                extra = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
                for member in tar.getmembers():
                    tar.extract(member, unpack, set_attrs=False, **extra)
        except (tarfile.TarError, EOFError, OSError) as exc:
            raise FetchError(f"{name} {version}: not a readable .crate file ({exc})") from None
        final = dest / top
        if final.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{top}.", suffix=".old", dir=dest))
            final.rename(old / top)
            (unpack / top).rename(final)
            shutil.rmtree(old)
        else:
            (unpack / top).rename(final)
        return final
    finally:
        part.unlink(missing_ok=True)
        if unpack is not None:
            shutil.rmtree(unpack, ignore_errors=True)


def main(argv: list[str]) -> int:
    args = list(argv)
    base = DEFAULT_BASE
    if args and args[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0
    if "--base" in args:
        i = args.index("--base")
        if i + 1 >= len(args):
            print("fetch_crate: --base needs a URL", file=sys.stderr)
            return 2
        base = args[i + 1]
        del args[i:i + 2]
    if len(args) != 4:
        print("fetch_crate: usage: fetch_crate.py NAME VERSION SHA256 DEST [--base URL]", file=sys.stderr)
        return 2
    name, version, sha256, dest = args
    try:
        path = fetch(name, version, sha256, Path(dest), base)
    except FetchError as exc:
        print(f"fetch_crate: {exc}", file=sys.stderr)
        return 1
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
