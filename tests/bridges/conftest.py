"""Fixtures for the bridge tests."""

from __future__ import annotations

import pytest
from bridge_test_frames import moving_frame

from gesturecast.frames import PoseFrame


@pytest.fixture
def frames() -> list[PoseFrame]:
    return [moving_frame(i, clock_now=100.0 + i / 30.0) for i in range(8)]
