# SPDX-License-Identifier: MIT
"""pour_virtual_board on the flashed image and on small hand-written images (assembled here with the
cross toolchain): the heartbeat, the watchdog, the flash erase against the watchdog, and bad input.

POUR_VB (the program) and POUR_ELF (build/cortex-m4's pour_firmware.elf) come from tests/virtual_board/CMakeLists.txt.
"""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

VB = os.environ["POUR_VB"]
ELF = os.environ["POUR_ELF"]
CC = shutil.which("arm-none-eabi-gcc")


def run(*args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run([VB, *args], capture_output=True, text=True, timeout=timeout)


def image(tmp_path: Path, body: str, origin: int = 0x08000000, nmi: str = "") -> str:
    """A Cortex-M4 image: the vector table (SP at the top of SRAM, reset to `start`, NMI to `nmi` if given),
    then body."""
    assert CC, "arm-none-eabi-gcc is needed (scripts/setup.sh's toolchain)"
    src = tmp_path / "t.S"
    src.write_text(
        ".syntax unified\n.thumb\n.section .text\n.word 0x20008000\n.word start + 1\n"
        + (".word nmi + 1\n" if nmi else "") + ".thumb_func\nstart:\n" + body + "\n.ltorg\n"
        + (".thumb_func\nnmi:\n" + nmi + "\n.ltorg\n" if nmi else "")
    )
    out = tmp_path / "t.elf"
    subprocess.run([CC, "-mcpu=cortex-m4", "-mthumb", "-nostdlib", f"-Wl,-Ttext=0x{origin:08x}", "-Wl,-e,start",
                    "-o", str(out), str(src)], check=True, capture_output=True)
    return str(out)


def test_flashed_image_boots_to_heartbeat():
    r = run("--elf", ELF, "--until-heartbeat", "--seconds", "5", "--print-can")
    assert r.returncode == 0, r.stderr
    assert "sha256 " in r.stderr
    ids = {line.split()[3] for line in r.stdout.splitlines() if " tx " in line}
    assert "001" in ids, r.stdout  # Heartbeat of node 0 (can/pour.dbc BO_ 1)
    assert "heartbeat at" in r.stdout


def test_drive_telemetry_goes_out_with_every_heartbeat():
    # A heartbeat tick queues four frames (Torque, Heartbeat, Identity, DriveTelemetry) into FDCAN1's TX FIFO
    # of three: before board_loop.c kept what does not fit for the next tick, DriveTelemetry never left (0 of 10).
    r = run("--elf", ELF, "--seconds", "1", "--print-can")
    assert r.returncode == 0, r.stderr
    ids = [line.split()[3] for line in r.stdout.splitlines() if " tx " in line]
    assert ids.count("001") == 10 and ids.count("004") == 10 and ids.count("007") == 10, sorted(set(ids))


def test_missed_watchdog_refresh_resets_the_chip():
    r = run("--elf", ELF, "--seconds", "3", "--stall-core-at", "500", "--stall-core-ms", "300",
            "--stop-on-reset")
    assert r.returncode == 0, r.stderr
    assert "reset at" in r.stderr and "IWDG: no refresh" in r.stderr, r.stderr


def test_healthy_run_has_no_reset():
    r = run("--elf", ELF, "--seconds", "3", "--stop-on-reset", "--bench")
    assert r.returncode == 0, r.stderr
    assert "reset at" not in r.stderr
    assert " 0 resets" in r.stdout


def test_ecc_error_on_the_calibration_page_does_not_loop_the_board():
    # Page 63 half-erased: the image's NMI clears ECCD, the calibration is corrupt (RUN refused), and the board
    # comes up to its heartbeat without a reset (before the fix it reset every 213 ms and never sent one).
    r = run("--elf", ELF, "--ecc-page", "63", "--seconds", "2", "--print-can", "--stop-on-reset")
    assert r.returncode == 0, r.stderr
    assert "reset at" not in r.stderr, r.stderr
    assert any(line.split()[3] == "001" for line in r.stdout.splitlines() if " tx " in line), r.stdout


IWDG_RLR_99 = """
    ldr r0, =0x40003000
    ldr r1, =0xCCCC
    str r1, [r0]
    ldr r1, =0x5555
    str r1, [r0]
    movs r1, #0
    str r1, [r0, #4]
    movs r1, #99
    str r1, [r0, #8]
"""
# RVU and PVU clear (5 LSI periods), then the key 0xAAAA loads the new RLR into the counter (RM0440 §41.3.2).
IWDG_RELOAD = """
3:  ldr r2, [r0, #0xC]
    cmp r2, #0
    bne 3b
    ldr r1, =0xAAAA
    str r1, [r0]
"""


def test_a_new_watchdog_reload_value_waits_for_the_next_reload(tmp_path):
    # RM0440 §41.3.2: started by 0xCCCC, the counter counts down from its reset value 0xFFF (512 ms at LSI / 4 and
    # 32 kHz); RLR 99 (12.5 ms) is loaded only by the next 0xAAAA, once RVU has cleared.
    r = run("--elf", image(tmp_path, IWDG_RLR_99 + "1: b 1b"), "--seconds", "0.4", "--stop-on-reset")
    assert r.returncode == 0 and "reset at" not in r.stderr, r.stderr
    r = run("--elf", image(tmp_path, IWDG_RLR_99 + IWDG_RELOAD + "1: b 1b"), "--seconds", "0.4", "--stop-on-reset")
    assert "IWDG: no refresh within 12 ms" in r.stderr, r.stderr
    at = float(r.stderr.split("reset at ")[1].split(" ms")[0])
    assert 12.0 < at < 13.5, r.stderr


def test_watchdog_shorter_than_page_erase_is_caught(tmp_path):
    # IWDG at LSI / 4 with RLR 99: 12.5 ms at 32 kHz, then a page erase (24.47 ms max): the chip resets inside it.
    body = IWDG_RLR_99 + IWDG_RELOAD + """
    ldr r0, =0x40022000
    ldr r1, =0x45670123
    str r1, [r0, #8]
    ldr r1, =0xCDEF89AB
    str r1, [r0, #8]
    ldr r1, =(1 << 1) | (63 << 3)
    str r1, [r0, #0x14]
    ldr r1, =(1 << 1) | (63 << 3) | (1 << 16)
    str r1, [r0, #0x14]
1:  b 1b
"""
    r = run("--elf", image(tmp_path, body), "--seconds", "1", "--stop-on-reset")
    assert "shorter than the flash page erase" in r.stderr, r.stderr
    assert "IWDG: no refresh" in r.stderr


def test_ecc_error_on_a_data_page_raises_the_nmi(tmp_path):
    # RM0440 §3.3.5: a double ECC error on a read sets FLASH_ECCR.ECCD and raises the NMI. The handler here reads
    # ECCR, then an unmapped address whose stop names the handler's PC: only an NMI with ECCD set gets there.
    nmi = """
    ldr r0, =0x40022018
    ldr r1, [r0]
    lsrs r1, r1, #31
    beq 2f
    ldr r0, =0x60000004
    ldr r1, [r0]
2:  b 2b
"""
    body = "ldr r0, =0x0801F800\nldr r1, [r0]\n1: b 1b"
    elf = image(tmp_path, body, nmi=nmi)
    r = run("--elf", elf, "--seconds", "0.1", "--ecc-page", "63")
    assert r.returncode == 1 and "unmapped address 0x60000004" in r.stderr, r.stderr
    r = run("--elf", elf, "--seconds", "0.1")  # the same read of an intact page: no NMI
    assert r.returncode == 0, r.stderr


def test_read_of_peripheral_without_model_stops_with_pc_address_name(tmp_path):
    r = run("--elf", image(tmp_path, "ldr r0, =0x40015400\nldr r1, [r0]\n1: b 1b"), "--seconds", "1")
    assert r.returncode == 1
    assert "0x40015400" in r.stderr and "SAI" in r.stderr and "pc 0x0800" in r.stderr, r.stderr


def test_unmapped_address_stops(tmp_path):
    r = run("--elf", image(tmp_path, "ldr r0, =0x60000000\nldr r1, [r0]\n1: b 1b"), "--seconds", "1")
    assert r.returncode == 1
    assert "unmapped address 0x60000000" in r.stderr and "pc 0x0800" in r.stderr, r.stderr


def test_uncovered_register_of_modelled_peripheral_stops(tmp_path):
    r = run("--elf", image(tmp_path, "ldr r0, =0x40021000\nldr r1, [r0, #0x14]\n1: b 1b"), "--seconds", "1")
    assert r.returncode == 1
    assert "offset 0x014 of RCC" in r.stderr, r.stderr


def test_host_elf_refused_by_name():
    r = run("--elf", VB)  # this program: a 64-bit x86 ELF
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "not the STM32G431 image: not a 32-bit little-endian ELF" in r.stderr


def test_32_bit_elf_of_another_machine_refused(tmp_path):
    p = tmp_path / "x86.elf"
    data = bytearray(Path(image(tmp_path, "1: b 1b")).read_bytes())
    data[18:20] = (3).to_bytes(2, "little")  # e_machine EM_386
    p.write_bytes(bytes(data))
    r = run("--elf", str(p))
    assert r.returncode == 2 and "not an ARM ELF (e_machine 3)" in r.stderr, r.stderr


def test_image_without_vector_table_refused(tmp_path):
    r = run("--elf", image(tmp_path, "1: b 1b", origin=0x08001000))
    assert r.returncode == 2 and "no vector table at 0x08000000" in r.stderr, r.stderr


def test_image_for_another_memory_map_refused(tmp_path):
    r = run("--elf", image(tmp_path, "1: b 1b", origin=0x00000000))
    assert r.returncode == 2 and "outside the 128 KB flash" in r.stderr, r.stderr


def test_not_an_elf_refused(tmp_path):
    p = tmp_path / "x.bin"
    p.write_bytes(b"\x00" * 100)
    r = run("--elf", str(p))
    assert r.returncode == 2 and "not an ELF file" in r.stderr


@pytest.mark.parametrize("args, message", [
    (["--seconds", "x"], "bad number for --seconds"),
    (["--seconds", "-1"], "--seconds must be"),
    (["--estop", "maybe"], "--estop must be open or closed"),
    (["--ecc-page", "5"], "--ecc-page must be 62 or 63"),
    (["--frobnicate"], "unknown option --frobnicate"),
    (["--elf", "/nonexistent.elf"], "cannot read /nonexistent.elf"),
])
def test_bad_options(args, message):
    r = run(*args)
    assert r.returncode == 2
    assert r.stderr.startswith("pour_virtual_board: ") and message in r.stderr and r.stderr.count("\n") == 1


def launcher(*args: str, tools: Path | None = None) -> subprocess.CompletedProcess[str]:
    import sys

    e = dict(os.environ, PYTHONPATH=str(tools or Path(__file__).resolve().parents[2] / "tools"))
    e.pop("POUR_BUILD_DIR", None)
    return subprocess.run([sys.executable, "-m", "pour.virtual_board", *args], capture_output=True, text=True,
                          timeout=120, env=e)


def test_launcher_finds_the_program_and_the_image():
    build = str(Path(VB).resolve().parents[1])
    r = launcher("--build-dir", build, "--help")
    # the launcher's own usage, then the program's options
    assert r.returncode == 0 and r.stdout.startswith("usage: pour-virtual-board"), r.stderr
    assert "\nusage: pour_virtual_board" in r.stdout, r.stdout
    r = launcher("--build-dir", build, "--until-heartbeat", "--seconds", "2")
    assert r.returncode == 0 and "heartbeat at" in r.stdout, r.stderr


def test_launcher_without_a_build_says_so(tmp_path, monkeypatch, capsys):
    # No build tree anywhere: paths.binary finds nothing (an editable install's finder would otherwise find this
    # checkout's build/host whatever PYTHONPATH says).
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
    from pour import paths, virtual_board

    monkeypatch.setattr(paths, "binary", lambda name, build_dir=None: None)
    assert virtual_board.main(["--build-dir", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pour_virtual_board not found" in err, err
    assert virtual_board.main(["--build-dir"]) == 2
    assert "--build-dir needs a folder" in capsys.readouterr().err
    # --help and --version need no build (a plain install of the tools answers them)
    assert virtual_board.main(["--build-dir", str(tmp_path), "--help"]) == 0
    assert capsys.readouterr().out.startswith("usage: pour-virtual-board")
    assert virtual_board.main(["--version"]) == 0
    assert capsys.readouterr().out.startswith("pour-virtual-board ")
