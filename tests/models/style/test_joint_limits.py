"""The soft joint limit: the identity inside a human range, smooth and bounded beyond it, never pulling the input
pose back; the shipped ranges are human."""

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.style.joint_limits import MARGIN, JointRanges, soft_ceiling
from gesturecast.models.style.params import STYLED_JOINTS

S = len(STYLED_JOINTS)


def box(half_width: float, angle: float) -> JointRanges:
    return JointRanges(np.full((S, 3), -half_width), np.full((S, 3), half_width), np.full(S, angle))


def test_motion_inside_the_range_leaves_bit_for_bit():
    ranges = box(1.0, 1.5)
    inside = np.random.default_rng(0).uniform(-0.5, 0.5, (20, S, 3))
    np.testing.assert_array_equal(ranges.limit(inside, np.zeros_like(inside)), inside)


def test_beyond_the_range_a_joint_bends_smoothly_and_never_past_the_margin():
    x = np.linspace(0.0, 5.0, 5001)
    y = soft_ceiling(x, np.array(1.0))
    assert y.max() <= 1.0 + MARGIN and np.all(np.diff(y) >= 0)
    slopes = np.diff(y) / np.diff(x)
    assert np.abs(np.diff(slopes)).max() < 1e-2  # no kink at the ceiling
    ranges = box(1.0, 1.2)
    styled = np.full((1, S, 3), 40.0)  # a wrapped head: far outside
    limited = ranges.limit(styled, np.zeros_like(styled))
    assert np.linalg.norm(limited, axis=-1).max() < 1.2 + MARGIN
    assert np.abs(limited).max() < 1.0 + MARGIN


def test_the_limit_never_pulls_the_input_pose_back():
    ranges = box(0.2, 0.3)
    given = np.full((3, S, 3), 0.5)  # the generator's own pose, outside the range
    np.testing.assert_array_equal(ranges.limit(given, given), given)
    pushed = ranges.limit(given + 2.0, given)
    assert np.all(pushed >= given) and np.all(pushed < given + MARGIN)


def test_the_shipped_ranges_are_human():
    ranges = JointRanges.load()
    degrees = dict(zip(STYLED_JOINTS, np.degrees(ranges.angle), strict=True))
    assert degrees["Neck"] < 70 and degrees["Head"] < 70  # a head never faces backwards
    assert 120 < degrees["LeftLowerArm"] < 165 and 120 < degrees["RightLowerArm"] < 165
    assert np.all(ranges.low <= ranges.high) and np.all(ranges.angle + MARGIN < np.pi)


def test_a_broken_range_file_is_a_one_line_error(tmp_path):
    path = tmp_path / "joint_ranges.json"
    path.write_text('{"format": "x"}')
    with pytest.raises(UserError, match="not a gesturecast-joint-ranges-1 file"):
        JointRanges.load(path)
