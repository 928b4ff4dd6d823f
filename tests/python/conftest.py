"""Shared pytest fixtures: where the CMake build put the binaries and modules."""
import os
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]


def find_build_dir() -> Path:
    """$RELIEF_SNAKE_BUILD_DIR if set, else <repo>/build."""
    env = os.environ.get("RELIEF_SNAKE_BUILD_DIR")
    return Path(env).resolve() if env else REPO_ROOT / "build"


@pytest.fixture(scope="session")
def build_dir() -> Path:
    path = find_build_dir()
    if not path.is_dir():
        pytest.fail(f"build directory {path} not found: build the project (cmake) or set RELIEF_SNAKE_BUILD_DIR")
    return path
