# SPDX-License-Identifier: MIT
"""Shared pytest fixtures: where the source tree and the ctest build tree are."""
import os
from pathlib import Path

import pytest

SOURCE_DIR = Path(os.environ.get("POUR_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD_DIR = Path(os.environ.get("POUR_BUILD_DIR", SOURCE_DIR / "build" / "host"))


@pytest.fixture
def source_dir() -> Path:
    return SOURCE_DIR


@pytest.fixture
def build_dir() -> Path:
    return BUILD_DIR
