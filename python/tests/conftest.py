import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "examples"))  # verlet.py


@pytest.fixture(scope="session")
def shelldyn():
    import shelldyn as sd
    return sd


@pytest.fixture(scope="session")
def cli():
    """The shelldyn executable of this build (SHELLDYN_CLI, set by ctest)."""
    path = os.environ.get("SHELLDYN_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("SHELLDYN_CLI not set (run through ctest)")
    return path
