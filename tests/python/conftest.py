"""Shared fixtures of the Python module's tests (tests/CMakeLists.txt runs them with pytest).

EPICHEAD_SHARED_DATA: ../shared/data (the real teabox video and CAN logs); EPICHEAD_BIN: the
built program, for the tests that check the module against the command line.
"""
import os
import pathlib

import pytest

import epichead

SHARED = pathlib.Path(os.environ.get("EPICHEAD_SHARED_DATA", pathlib.Path(__file__).parents[3] / "shared" / "data"))


def shared_dir(name):
    """A folder of ../shared/data, or the test is skipped where the checkout has none beside it."""
    path = SHARED / name
    if not path.is_dir():
        pytest.skip(f"no real data at {path}")
    return path


@pytest.fixture(scope="session")
def teabox_dir():
    return shared_dir("teabox")


@pytest.fixture(scope="session")
def teabox(teabox_dir):
    return epichead.Sequence(str(teabox_dir))


@pytest.fixture(scope="session")
def can_dir():
    return shared_dir("can")


@pytest.fixture(scope="session")
def program():
    path = os.environ.get("EPICHEAD_BIN", "")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("EPICHEAD_BIN is not set to the built program")
    return path
