import numpy as np
import pytest

from gesturecast.models.motion import rotations as R

ORDERS = ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]


@pytest.fixture
def random_quats():
    return R.quat_normalize(np.random.default_rng(0).normal(size=(500, 4)))


def _same_rotation(a, b):
    return np.abs(np.abs(np.sum(a * b, axis=-1)) - 1.0).max()


@pytest.mark.parametrize("order", ORDERS)
def test_euler_round_trip(random_quats, order):
    back = R.quat_from_euler(R.quat_to_euler(random_quats, order), order)
    assert _same_rotation(back, random_quats) < 1e-12


def test_euler_is_intrinsic_product_of_channel_rotations():
    angles = np.radians([30.0, -45.0, 60.0])
    q = R.quat_from_euler(angles, "ZYX")
    expected = R.quat_mul(
        R.quat_mul(R.quat_from_axis_angle([0, 0, angles[0]]), R.quat_from_axis_angle([0, angles[1], 0])),
        R.quat_from_axis_angle([angles[2], 0, 0]),
    )
    assert _same_rotation(q, expected) < 1e-12


def test_matrix_axis_angle_and_6d_round_trips(random_quats):
    assert _same_rotation(R.quat_from_matrix(R.quat_to_matrix(random_quats)), random_quats) < 1e-12
    assert _same_rotation(R.quat_from_axis_angle(R.quat_to_axis_angle(random_quats)), random_quats) < 1e-12
    assert _same_rotation(R.quat_from_6d(R.quat_to_6d(random_quats)), random_quats) < 1e-12


def test_rotate_matches_matrix(random_quats):
    v = np.random.default_rng(1).normal(size=(500, 3))
    np.testing.assert_allclose(R.quat_rotate(random_quats, v),
                               np.einsum("nij,nj->ni", R.quat_to_matrix(random_quats), v), atol=1e-12)


def test_mul_applies_right_operand_first(random_quats):
    a, b = random_quats[:250], random_quats[250:]
    v = np.random.default_rng(2).normal(size=(250, 3))
    np.testing.assert_allclose(R.quat_rotate(R.quat_mul(a, b), v), R.quat_rotate(a, R.quat_rotate(b, v)), atol=1e-12)


def test_slerp_endpoints_and_midpoint():
    a = R.quat_identity()
    b = R.quat_from_axis_angle(np.array([0.0, np.pi / 2, 0.0]))
    assert _same_rotation(R.quat_slerp(a, b, 0.0), a) < 1e-12
    assert _same_rotation(R.quat_slerp(a, b, 1.0), b) < 1e-12
    mid = R.quat_slerp(a, b, 0.5)
    assert _same_rotation(mid, R.quat_from_axis_angle(np.array([0.0, np.pi / 4, 0.0]))) < 1e-12


def test_between_and_yaw():
    u = np.array([1.0, 0.0, 0.0])
    v = np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(R.quat_rotate(R.quat_between(u, v), u), v, atol=1e-12)
    np.testing.assert_allclose(R.quat_rotate(R.quat_between(u, -u), u), -u, atol=1e-12)
    yaw = np.array([-2.0, 0.3, 1.5])
    np.testing.assert_allclose(R.quat_yaw(R.quat_from_yaw(yaw)), yaw, atol=1e-12)
