"""Shared fixtures: the xtask binary the bit-for-bit test compares against, and GPU policy."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def xtask():
    """The path of the `xtask` binary (``SOFT_SHADOWS_XTASK``, else built with cargo)."""
    path = os.environ.get("SOFT_SHADOWS_XTASK")
    if path:
        return pathlib.Path(path)
    subprocess.run(["cargo", "build", "-q", "-p", "xtask"], cwd=ROOT, check=True)
    return ROOT / "target" / "debug" / "xtask"


@pytest.fixture(scope="session")
def require_gpu():
    """True where a GPU technique must not be refused for want of an adapter (CI)."""
    return os.environ.get("SHADOW_REQUIRE_GPU") == "1"
