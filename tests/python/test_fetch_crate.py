# SPDX-License-Identifier: MIT
"""scripts/lib/fetch_crate.py, which scripts/setup.sh fetches the pinned crates with: a file whose sha256
differs from the pin is refused by name and leaves nothing behind, an archive member outside the crate's
folder is refused, a good file is unpacked and replaces an older copy only once complete, and bad input is
one line and a non-zero exit. The crate files are made here and served from file:// URLs."""
from __future__ import annotations

import hashlib
import io
import os
import subprocess
import sys
import tarfile
from pathlib import Path

SOURCE = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCRIPT = SOURCE / "scripts" / "lib" / "fetch_crate.py"
# setup.sh runs it with Debian's interpreter, before the venv exists.
PYTHON = "/usr/bin/python3" if Path("/usr/bin/python3").is_file() else sys.executable


def make_crate(base: Path, name: str, version: str, members: dict[str, bytes]) -> str:
    """Writes base/NAME/NAME-VERSION.crate (a gzipped tar of members); returns its sha256."""
    folder = base / name
    folder.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tar:
        for path, data in members.items():
            info = tarfile.TarInfo(path)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    blob = buf.getvalue()
    (folder / f"{name}-{version}.crate").write_bytes(blob)
    return hashlib.sha256(blob).hexdigest()


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, str(SCRIPT), *args], capture_output=True, text=True, timeout=60)


def test_good_file_is_unpacked(tmp_path):
    served = tmp_path / "served"
    sha = make_crate(served, "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// one\n",
                                               "demo-1.2.3/Cargo.toml": b"[package]\n"})
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", sha, str(dest), "--base", served.as_uri())
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == str((dest / "demo-1.2.3").resolve())
    assert (dest / "demo-1.2.3" / "src" / "lib.rs").read_bytes() == b"// one\n"
    assert sorted(p.name for p in dest.iterdir()) == ["demo-1.2.3"]  # no temporary left


def test_wrong_hash_is_refused_by_name_and_leaves_nothing(tmp_path):
    served = tmp_path / "served"
    sha = make_crate(served, "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// one\n"})
    wrong = ("0" if sha[0] != "0" else "1") + sha[1:]
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", wrong, str(dest), "--base", served.as_uri())
    assert res.returncode == 1
    line = res.stderr.strip()
    assert "\n" not in line and "Traceback" not in res.stderr
    assert "demo 1.2.3" in line and sha in line and wrong in line and "refused" in line
    assert res.stdout == ""
    assert list(dest.iterdir()) == []


def test_wrong_hash_keeps_the_older_copy(tmp_path):
    served = tmp_path / "served"
    sha = make_crate(served, "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// one\n"})
    dest = tmp_path / "deps"
    assert run("demo", "1.2.3", sha, str(dest), "--base", served.as_uri()).returncode == 0
    make_crate(served, "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// tampered\n"})
    res = run("demo", "1.2.3", sha, str(dest), "--base", served.as_uri())
    assert res.returncode == 1 and "refused" in res.stderr
    assert (dest / "demo-1.2.3" / "src" / "lib.rs").read_bytes() == b"// one\n"
    assert sorted(p.name for p in dest.iterdir()) == ["demo-1.2.3"]


def test_good_file_replaces_an_older_copy(tmp_path):
    served = tmp_path / "served"
    dest = tmp_path / "deps"
    (dest / "demo-1.2.3" / "stale").mkdir(parents=True)
    sha = make_crate(served, "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"// two\n"})
    assert run("demo", "1.2.3", sha, str(dest), "--base", served.as_uri()).returncode == 0
    assert not (dest / "demo-1.2.3" / "stale").exists()
    assert (dest / "demo-1.2.3" / "src" / "lib.rs").read_bytes() == b"// two\n"
    assert sorted(p.name for p in dest.iterdir()) == ["demo-1.2.3"]


def test_member_outside_the_crate_folder_is_refused(tmp_path):
    served = tmp_path / "served"
    dest = tmp_path / "deps"
    for i, bad in enumerate(["demo-1.2.3/../escape.rs", "/abs/escape.rs", "other-1.0.0/lib.rs"]):
        sha = make_crate(served, "demo", "1.2.3", {"demo-1.2.3/src/lib.rs": b"x", bad: b"y"})
        res = run("demo", "1.2.3", sha, str(dest), "--base", served.as_uri())
        assert res.returncode == 1, bad
        assert "outside demo-1.2.3/" in res.stderr and "Traceback" not in res.stderr, res.stderr
        assert list(dest.iterdir()) == [], bad
    assert not (tmp_path / "escape.rs").exists()


def test_not_a_crate_file_is_refused(tmp_path):
    served = tmp_path / "served"
    (served / "demo").mkdir(parents=True)
    blob = b"not a gzip file"
    (served / "demo" / "demo-1.2.3.crate").write_bytes(blob)
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", hashlib.sha256(blob).hexdigest(), str(dest), "--base", served.as_uri())
    assert res.returncode == 1 and "not a readable .crate file" in res.stderr
    assert "Traceback" not in res.stderr and list(dest.iterdir()) == []


def test_missing_file_is_one_line(tmp_path):
    dest = tmp_path / "deps"
    res = run("demo", "1.2.3", "a" * 64, str(dest), "--base", (tmp_path / "nowhere").as_uri())
    assert res.returncode == 1 and res.stderr.startswith("fetch_crate: cannot download ")
    assert res.stderr.count("\n") == 1 and list(dest.iterdir()) == []


def test_bad_arguments_are_one_line(tmp_path):
    dest = str(tmp_path / "deps")
    cases = [([], 2, "usage"), (["demo", "1.2.3", dest], 2, "usage"),
             (["../x", "1.2.3", "a" * 64, dest], 1, "not a crate name"),
             (["demo", "one", "a" * 64, dest], 1, "not a crate version"),
             (["demo", "1.2.3", "A" * 64, dest], 1, "not a sha256"),
             (["demo", "1.2.3", "a" * 64, dest, "--base"], 2, "--base needs a URL")]
    for args, status, text in cases:
        res = run(*args)
        assert res.returncode == status, args
        assert text in res.stderr and res.stderr.count("\n") == 1, (args, res.stderr)
    assert not (tmp_path / "deps").exists()


def test_help():
    res = run("--help")
    assert res.returncode == 0 and "NAME VERSION SHA256 DEST" in res.stdout
