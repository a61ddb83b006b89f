"""What the tests need beyond the package: the shared scenes, the `rtgi`
binary (for the comparison of the two front ends) and Embree.

A test that lacks one is skipped with a message saying what is missing,
unless the matching RTGI_REQUIRE_* variable is 1 (as in CI): then it fails,
so that a green run cannot mean that nothing real was tried.
"""

import os
import shutil
from pathlib import Path

import pytest

WORKSPACE = Path(__file__).resolve().parents[2]


def required(variable):
    return os.environ.get(variable) == "1"


def missing(what, variable):
    """Skips the test, or fails it when `variable` is 1."""
    if required(variable):
        pytest.fail(f"{what} ({variable}=1 requires it)")
    pytest.skip(what)


def scenes_folder():
    return Path(os.environ.get("RTGI_SCENES") or WORKSPACE / ".." / "shared" / "scenes")


@pytest.fixture(scope="session")
def bunny_path():
    path = scenes_folder() / "bunny" / "stanford-bunny.obj"
    if not path.is_file():
        missing(f"the shared scenes are not at {scenes_folder()} (set RTGI_SCENES)", "RTGI_REQUIRE_SCENES")
    return path


@pytest.fixture(scope="session")
def bunny(bunny_path):
    import rtgi

    return rtgi.load(bunny_path)


@pytest.fixture(scope="session")
def rtgi_binary():
    """The `rtgi` command line: $RTGI_BIN, else the workspace's build (debug or release), else PATH."""
    given = os.environ.get("RTGI_BIN")
    if given:
        if not Path(given).is_file():
            pytest.fail(f"RTGI_BIN={given}: no such file")
        return given
    target = Path(os.environ.get("CARGO_TARGET_DIR") or WORKSPACE / "target")
    for candidate in [target / "debug" / "rtgi", target / "release" / "rtgi", shutil.which("rtgi")]:
        if candidate and Path(candidate).is_file():
            return str(candidate)
    missing("no rtgi binary (cargo build -p rtgi, or set RTGI_BIN)", "RTGI_REQUIRE_SCENES")
