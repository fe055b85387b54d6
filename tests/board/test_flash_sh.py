# SPDX-License-Identifier: MIT
"""scripts/flash.sh's refusal paths with the real openocd and no probe attached (this machine has none):
no image, a file that is not an ELF, a host ELF, no openocd, too many arguments, and an ARM image that
reaches openocd, which finds no ST-LINK: each a clear message and its own exit status."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[2]))
FLASH = SOURCE / "scripts" / "flash.sh"


def flash(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(FLASH), *args], capture_output=True, text=True, timeout=60,
                          env={**os.environ, **(env or {})})


def test_refuses_a_missing_image(tmp_path):
    r = flash(str(tmp_path / "none.elf"))
    assert r.returncode == 2
    assert "no image at" in r.stderr and "cmake --build --preset cortex-m4" in r.stderr


def test_refuses_a_file_that_is_not_an_elf(tmp_path):
    image = tmp_path / "pour_firmware.bin"
    image.write_bytes(b"\x00\x10\x00\x20" * 16)
    r = flash(str(image))
    assert r.returncode == 2 and "not an ELF file" in r.stderr


def test_refuses_a_host_elf():
    r = flash(sys.executable)
    assert r.returncode == 2 and "not a 32-bit ARM image" in r.stderr


def test_refuses_too_many_arguments(tmp_path):
    r = flash("a.elf", "b.elf")
    assert r.returncode == 2 and "usage" in r.stderr


@pytest.fixture()
def arm_elf(tmp_path) -> Path:
    gcc = shutil.which("arm-none-eabi-gcc")
    assert gcc, "arm-none-eabi-gcc missing: run scripts/setup.sh"
    image = tmp_path / "tiny.elf"
    subprocess.run([gcc, "-mcpu=cortex-m4", "-mthumb", "-nostdlib", "-x", "c", "-", "-o", str(image)],
                   input="void _start(void) { for (;;) { } }\n", text=True, check=True)
    return image


def test_says_so_when_openocd_is_missing(arm_elf):
    r = flash(str(arm_elf), env={"OPENOCD": "/nonexistent/openocd"})
    assert r.returncode == 2 and "openocd not found" in r.stderr


def test_says_no_probe_when_none_is_attached(arm_elf):
    assert shutil.which("openocd"), "openocd missing: run scripts/setup.sh"
    r = flash(str(arm_elf))
    assert r.returncode == 3, r.stderr
    assert "no ST-LINK probe found" in r.stderr
