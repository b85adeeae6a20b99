"""Shared fixtures of the Python package's tests: the command-line tool built by cargo, the
real characters of ../shared/data (a missing folder fails the tests, never skips them)."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data"


def data(relative):
    """A file of ../shared/data; fails loudly when it is missing."""
    path = SHARED / relative
    if not path.exists():
        raise FileNotFoundError(f"{path} is missing: the tests read the real characters from there")
    return path


@pytest.fixture(scope="session")
def cli():
    """Runs the `atlas-skin` binary of target/release (ATLAS_SKIN_BIN overrides it)."""
    binary = Path(os.environ.get("ATLAS_SKIN_BIN", ROOT / "target" / "release" / "atlas-skin"))
    if not binary.exists():
        raise FileNotFoundError(f"{binary} is missing: build it with cargo build --release -p atlas-skin-cli")

    def run(*args, check=True):
        return subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, check=check)

    return run


@pytest.fixture(scope="session")
def demo():
    """The demo character's arrays (generated once: about 2 s of CPU). Tests copy before
    changing them."""
    import atlas_skin

    return atlas_skin.demo()
