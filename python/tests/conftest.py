"""Shared set-up of the Python package's tests: the package from this source tree (python/), and
the `fovea` tool the tests compare against (FOVEA_CLI, else the one beside the library loaded)."""
import os
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.normpath(os.path.join(os.path.dirname(__file__), "..")))

import fovea  # noqa: E402  (after the path is set)


def cli_path():
    p = os.environ.get("FOVEA_CLI") or os.path.join(os.path.dirname(fovea.library_path()), "fovea")
    return p if os.path.isfile(p) and os.access(p, os.X_OK) else None


@pytest.fixture(scope="session")
def cli():
    """Runs the fovea tool: cli("render", ...) -> CompletedProcess (text)."""
    path = cli_path()
    if path is None:
        pytest.skip("no fovea tool beside the library (set FOVEA_CLI)")

    def run(*args, check=True):
        r = subprocess.run([path, *map(str, args)], capture_output=True, text=True, timeout=120)
        if check and r.returncode != 0:
            raise AssertionError(f"fovea {' '.join(map(str, args))}: exit {r.returncode}: {r.stderr.strip()}")
        return r
    return run


@pytest.fixture(scope="module")
def cornell():
    with fovea.Scene("cornell") as s:
        yield s
