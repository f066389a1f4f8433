"""Paths for the tests of the covtrack Python module (client/python).

CTest runs them (tests/python/CMakeLists.txt) with COVTRACK_SOURCE_DIR and
COVTRACK_BINARY_DIR set and PYTHONPATH at the built module; by hand:
    PYTHONPATH=build/client/python tests/netns_run.sh /usr/bin/python3 -m pytest tests/python -q
"""
import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("COVTRACK_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BINARY_DIR = pathlib.Path(os.environ.get("COVTRACK_BINARY_DIR", SOURCE_DIR / "build"))


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def covtrackd():
    return BINARY_DIR / "server" / "covtrackd"


@pytest.fixture(scope="session")
def covtrack_cli():
    return BINARY_DIR / "tools" / "covtrack" / "covtrack"
