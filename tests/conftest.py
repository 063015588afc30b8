"""Shared fixtures: where the real data lives (../shared/data beside the repository)."""

import sys
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO_ROOT.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The read-only real data folder; tests that need it are skipped when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared data not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session")
def tiny_model(tmp_path_factory, shared_data):
    """(training checkpoint, bundle folder) of the ``tiny`` preset trained once per session (~10 s) on
    cuts of the shared ZeroEGGS take; built by tests/models/train_fixtures.py."""
    helpers = str(REPO_ROOT / "tests" / "models")
    if helpers not in sys.path:
        sys.path.insert(0, helpers)
    from train_fixtures import train_tiny_bundle

    return train_tiny_bundle(tmp_path_factory.mktemp("tiny_model"), shared_data / "zeggs")
