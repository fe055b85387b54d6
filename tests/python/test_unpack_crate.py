# SPDX-License-Identifier: MIT
"""scripts/lib/unpack_crate.py, which scripts/setup.sh unpacks the pinned crates with once cargo has fetched
them: a file whose sha256 differs from the pin is refused by name and leaves nothing behind, an archive
member outside the crate's folder is refused, a good file is unpacked and replaces an older copy only once
complete, and bad input is one line and a non-zero exit. The crate files are made here."""
from __future__ import annotations

import hashlib
import io
import os
import subprocess
import sys
import tarfile
from pathlib import Path

SOURCE = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCRIPT = SOURCE / "scripts" / "lib" / "unpack_crate.py"
# setup.sh runs it with Debian's interpreter, before the venv exists.
PYTHON = "/usr/bin/python3" if Path("/usr/bin/python3").is_file() else sys.executable


def make_crate(folder: Path, name: str, version: str, members: dict[str, bytes]) -> tuple[Path, str]:
    """Writes folder/NAME-VERSION.crate (a gzipped tar of members), as cargo's cache holds it; returns its
    path and sha256."""
    folder.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tar:
        for path, data in members.items():
            info = tarfile.TarInfo(path)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    blob = buf.getvalue()
    crate = folder / f"{name}-{version}.crate"
    crate.write_bytes(blob)
    return crate, hashlib.sha256(blob).hexdigest()


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, str(SCRIPT), *args], capture_output=True, text=True, timeout=60)


def test_good_file_is_unpacked(tmp_path):
    crate, sha = make_crate(tmp_path / "cache", "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// one\n",
                                                                  "demo-1.2.3/Cargo.toml": b"[package]\n"})
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", sha, str(crate), str(dest))
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == str((dest / "demo-1.2.3").resolve())
    assert (dest / "demo-1.2.3" / "src" / "lib.rs").read_bytes() == b"// one\n"
    assert sorted(p.name for p in dest.iterdir()) == ["demo-1.2.3"]  # no temporary left
    assert crate.is_file()  # cargo's cached copy is read, not moved


def test_wrong_hash_is_refused_by_name_and_leaves_nothing(tmp_path):
    crate, sha = make_crate(tmp_path / "cache", "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// one\n"})
    wrong = ("0" if sha[0] != "0" else "1") + sha[1:]
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", wrong, str(crate), str(dest))
    assert res.returncode == 1
    line = res.stderr.strip()
    assert "\n" not in line and "Traceback" not in res.stderr
    assert "demo 1.2.3" in line and sha in line and wrong in line and "refused" in line
    assert res.stdout == ""
    assert list(dest.iterdir()) == []


def test_wrong_hash_keeps_the_older_copy(tmp_path):
    crate, sha = make_crate(tmp_path / "cache", "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// one\n"})
    dest = tmp_path / "deps"
    assert run("demo", "1.2.3", sha, str(crate), str(dest)).returncode == 0
    make_crate(tmp_path / "cache", "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// tampered\n"})
    res = run("demo", "1.2.3", sha, str(crate), str(dest))
    assert res.returncode == 1 and "refused" in res.stderr
    assert (dest / "demo-1.2.3" / "src" / "lib.rs").read_bytes() == b"// one\n"
    assert sorted(p.name for p in dest.iterdir()) == ["demo-1.2.3"]


def test_good_file_replaces_an_older_copy(tmp_path):
    dest = tmp_path / "deps"
    (dest / "demo-1.2.3" / "stale").mkdir(parents=True)
    crate, sha = make_crate(tmp_path / "cache", "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// two\n"})
    assert run("demo", "1.2.3", sha, str(crate), str(dest)).returncode == 0
    assert not (dest / "demo-1.2.3" / "stale").exists()
    assert (dest / "demo-1.2.3" / "src" / "lib.rs").read_bytes() == b"// two\n"
    assert sorted(p.name for p in dest.iterdir()) == ["demo-1.2.3"]


def test_member_outside_the_crate_folder_is_refused(tmp_path):
    dest = tmp_path / "deps"
    for bad in ["demo-1.2.3/../escape.rs", "/abs/escape.rs", "other-1.0.0/lib.rs"]:
        crate, sha = make_crate(tmp_path / "cache", "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"x", bad: b"y"})
        res = run("demo", "1.2.3", sha, str(crate), str(dest))
        assert res.returncode == 1, bad
        assert "outside demo-1.2.3/" in res.stderr and "Traceback" not in res.stderr, res.stderr
        assert list(dest.iterdir()) == [], bad
    assert not (tmp_path / "escape.rs").exists()


def test_link_member_is_refused(tmp_path):
    folder = tmp_path / "cache"
    folder.mkdir()
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tar:
        info = tarfile.TarInfo("demo-1.2.3/src/lib.rs")
        info.type = tarfile.SYMTYPE
        info.linkname = "/etc/passwd"
        tar.addfile(info)
    crate = folder / "demo-1.2.3.crate"
    crate.write_bytes(buf.getvalue())
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", hashlib.sha256(buf.getvalue()).hexdigest(), str(crate), str(dest))
    assert res.returncode == 1 and "not a plain file or folder" in res.stderr, res.stderr
    assert list(dest.iterdir()) == []


def test_not_a_crate_file_is_refused(tmp_path):
    crate = tmp_path / "demo-1.2.3.crate"
    blob = b"not a gzip file"
    crate.write_bytes(blob)
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", hashlib.sha256(blob).hexdigest(), str(crate), str(dest))
    assert res.returncode == 1 and "not a readable .crate file" in res.stderr
    assert "Traceback" not in res.stderr and list(dest.iterdir()) == []


def test_missing_file_is_one_line(tmp_path):
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", "a" * 64, str(tmp_path / "nowhere.crate"), str(dest))
    assert res.returncode == 1 and res.stderr.startswith("unpack_crate: no file ")
    assert res.stderr.count("\n") == 1 and not dest.exists()


def test_bad_arguments_are_one_line(tmp_path):
    dest = str(tmp_path / "deps")
    crate = str(tmp_path / "demo-1.2.3.crate")
    cases = [([], 2, "usage"), (["demo", "1.2.3", "a" * 64, dest], 2, "usage"),
             (["../x", "1.2.3", "a" * 64, crate, dest], 1, "not a crate name"),
             (["demo", "one", "a" * 64, crate, dest], 1, "not a crate version"),
             (["demo", "1.2.3", "A" * 64, crate, dest], 1, "not a sha256")]
    for args, status, text in cases:
        res = run(*args)
        assert res.returncode == status, args
        assert text in res.stderr and res.stderr.count("\n") == 1, (args, res.stderr)
    assert not (tmp_path / "deps").exists()


def test_help():
    res = run("--help")
    assert res.returncode == 0 and "NAME VERSION SHA256 CRATE_FILE DEST" in res.stdout
