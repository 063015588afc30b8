import numpy as np
import pytest

from gesturecast.bridges.coords import FRAMES, INTERNAL, UNITY, UNREAL, coordinate_frame
from gesturecast.errors import UserError
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_mul, quat_rotate

S = np.sqrt(0.5)

# frame, internal position, expected position
POSITIONS = [
    (UNITY, [1.0, 2.0, 3.0], [-1.0, 2.0, 3.0]),
    (UNREAL, [1.0, 2.0, 3.0], [300.0, -100.0, 200.0]),  # forward = +Z, right = -X, up = +Y, cm
    (INTERNAL, [1.0, 2.0, 3.0], [1.0, 2.0, 3.0]),
    (UNREAL, [0.0, 1.0, 0.0], [0.0, 0.0, 100.0]),  # up stays up
]

# frame, internal XYZW, expected XYZW
ROTATIONS = [
    (UNITY, [0.1, 0.2, 0.3, 0.9], [0.1, -0.2, -0.3, 0.9]),  # docs/architecture.md, Conventions: q = (x, -y, -z, w)
    (UNREAL, [0.1, 0.2, 0.3, 0.9], [-0.3, 0.1, -0.2, 0.9]),
    (INTERNAL, [0.1, 0.2, 0.3, 0.9], [0.1, 0.2, 0.3, 0.9]),
    (UNREAL, [0.0, S, 0.0, S], [0.0, 0.0, -S, S]),  # yaw about up → about Unreal Z, sign flips with handedness
]


@pytest.mark.parametrize(("frame", "p", "expected"), POSITIONS)
def test_positions(frame, p, expected):
    np.testing.assert_allclose(frame.position(np.array(p)), expected, atol=1e-12)


@pytest.mark.parametrize(("frame", "q", "expected"), ROTATIONS)
def test_rotations(frame, q, expected):
    np.testing.assert_allclose(frame.rotation(np.array(q)), expected, atol=1e-12)


@pytest.mark.parametrize("frame", list(FRAMES.values()))
def test_converted_rotation_applied_to_converted_vector(frame):
    rng = np.random.default_rng(0)
    q = quat_from_axis_angle(rng.normal(size=(64, 3)))  # (64, 4)
    v = rng.normal(size=(64, 3))
    np.testing.assert_allclose(
        quat_rotate(frame.rotation(q), frame.position(v)), frame.position(quat_rotate(q, v)), atol=1e-9
    )


@pytest.mark.parametrize("frame", list(FRAMES.values()))
def test_conversion_preserves_composition_and_inverts(frame):
    rng = np.random.default_rng(1)
    a, b = quat_from_axis_angle(rng.normal(size=(2, 16, 3)))
    composed = quat_mul(frame.rotation(a), frame.rotation(b))
    np.testing.assert_allclose(frame.rotation(quat_mul(a, b)), composed, atol=1e-12)
    p = rng.normal(size=(16, 3))
    np.testing.assert_allclose(frame.position(p) @ frame.to_internal_matrix().T, p, atol=1e-12)


def test_unity_and_unreal_are_left_handed():
    assert INTERNAL.handedness_sign == 1.0
    assert UNITY.handedness_sign == -1.0
    assert UNREAL.handedness_sign == -1.0


def test_unknown_frame_is_a_user_error():
    assert coordinate_frame("unity") is UNITY
    with pytest.raises(UserError, match="unknown coordinate frame 'blender'"):
        coordinate_frame("blender")
