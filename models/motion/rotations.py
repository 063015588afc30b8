"""Quaternion and rotation helpers (numpy, float64 by default).

Conventions (docs/architecture.md, "Conventions"): quaternions are **XYZW**, rotations act on column vectors, a product
``quat_mul(a, b)`` applies ``b`` first, then ``a`` (like the matrix product ``A @ B``). Every
function broadcasts over leading dimensions: ``(..., 4)`` quaternions, ``(..., 3)`` vectors.
"""

from __future__ import annotations

import numpy as np

_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}


def quat_identity(shape: tuple[int, ...] = ()) -> np.ndarray:
    """Identity quaternions of the given leading shape, ``(*shape, 4)``."""
    q = np.zeros((*shape, 4))
    q[..., 3] = 1.0
    return q


def quat_normalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternions with a non-negative w (one canonical sign per rotation)."""
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., 3:4] < 0, -q, q)


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a ⊗ b`` (apply b, then a). (..., 4) x (..., 4) -> (..., 4)."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=-1,
    )


def quat_conj(q: np.ndarray) -> np.ndarray:
    """Conjugate, the inverse of a unit quaternion."""
    return q * np.array([-1.0, -1.0, -1.0, 1.0])


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors: (..., 4), (..., 3) -> (..., 3)."""
    xyz, w = q[..., :3], q[..., 3:4]
    t = 2.0 * np.cross(xyz, v)
    return v + w * t + np.cross(xyz, t)


def quat_from_axis_angle(axis_angle: np.ndarray) -> np.ndarray:
    """Rotation vectors (axis * angle in radians), (..., 3) -> (..., 4)."""
    angle = np.linalg.norm(axis_angle, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(half)/angle with its limit 0.5 at angle -> 0
    scale = np.where(angle > 1e-12, np.sin(half) / np.maximum(angle, 1e-12), 0.5 - angle**2 / 48.0)
    return np.concatenate([axis_angle * scale, np.cos(half)], axis=-1)


def quat_to_axis_angle(q: np.ndarray) -> np.ndarray:
    """(..., 4) -> rotation vectors (..., 3), angle in [0, pi]."""
    q = quat_normalize(q)
    sin_half = np.linalg.norm(q[..., :3], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(sin_half, q[..., 3:4])
    scale = np.where(sin_half > 1e-12, angle / np.maximum(sin_half, 1e-12), 2.0)
    return q[..., :3] * scale


def quat_from_euler(angles: np.ndarray, order: str) -> np.ndarray:
    """Intrinsic Euler angles in radians, as BVH writes them.

    ``order`` names the axes in channel order, e.g. ``"ZYX"`` for ``Zrotation Yrotation
    Xrotation``; the rotation is ``R = R_axis0 @ R_axis1 @ R_axis2``. (..., 3) -> (..., 4).
    """
    q = quat_identity(angles.shape[:-1])
    for i, axis in enumerate(order.upper()):
        vec = np.zeros((*angles.shape[:-1], 3))
        vec[..., _AXIS_INDEX[axis]] = angles[..., i]
        q = quat_mul(q, quat_from_axis_angle(vec))
    return q


def quat_to_euler(q: np.ndarray, order: str) -> np.ndarray:
    """Inverse of :func:`quat_from_euler` (radians, channel order). (..., 4) -> (..., 3)."""
    m = quat_to_matrix(q)
    i, j, k = (_AXIS_INDEX[a] for a in order.upper())
    # sign of the permutation (i, j, k): +1 for cyclic orders such as XYZ, -1 for e.g. ZYX
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    middle = np.arcsin(np.clip(sign * m[..., i, k], -1.0, 1.0))
    gimbal = np.abs(m[..., i, k]) > 1.0 - 1e-9
    first = np.where(
        gimbal,
        np.arctan2(sign * m[..., k, j], m[..., j, j]),
        np.arctan2(-sign * m[..., j, k], m[..., k, k]),
    )
    last = np.where(gimbal, 0.0, np.arctan2(-sign * m[..., i, j], m[..., i, i]))
    return np.stack([first, middle, last], axis=-1)


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """(..., 4) -> rotation matrices (..., 3, 3)."""
    x, y, z, w = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def quat_from_matrix(m: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) -> unit quaternions (..., 4), numerically stable branch."""
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    candidates = np.stack(
        [
            np.stack([1 + m00 - m11 - m22, m[..., 1, 0] + m[..., 0, 1],
                      m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] - m[..., 1, 2]], -1),
            np.stack([m[..., 1, 0] + m[..., 0, 1], 1 - m00 + m11 - m22,
                      m[..., 2, 1] + m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0]], -1),
            np.stack([m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] + m[..., 1, 2],
                      1 - m00 - m11 + m22, m[..., 1, 0] - m[..., 0, 1]], -1),
            np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                      m[..., 1, 0] - m[..., 0, 1], 1 + m00 + m11 + m22], -1),
        ],
        axis=-2,
    )  # (..., 4 candidates, 4)
    best = np.argmax(np.stack([m00 - m11 - m22, -m00 + m11 - m22, -m00 - m11 + m22,
                               m00 + m11 + m22], -1), axis=-1)
    q = np.take_along_axis(candidates, best[..., None, None], axis=-2)[..., 0, :]
    return quat_normalize(q)


def matrix_to_6d(m: np.ndarray) -> np.ndarray:
    """Continuous 6D representation (Zhou et al. 2019): first two matrix columns. (..., 3, 3) -> (..., 6)."""
    return np.concatenate([m[..., :, 0], m[..., :, 1]], axis=-1)


def matrix_from_6d(d6: np.ndarray) -> np.ndarray:
    """Gram-Schmidt the two columns back to a rotation matrix. (..., 6) -> (..., 3, 3)."""
    a = d6[..., :3] / np.linalg.norm(d6[..., :3], axis=-1, keepdims=True)
    b = d6[..., 3:] - np.sum(a * d6[..., 3:], axis=-1, keepdims=True) * a
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    return np.stack([a, b, np.cross(a, b)], axis=-1)


def quat_to_6d(q: np.ndarray) -> np.ndarray:
    """(..., 4) -> (..., 6) (:func:`matrix_to_6d`)."""
    return matrix_to_6d(quat_to_matrix(q))


def quat_from_6d(d6: np.ndarray) -> np.ndarray:
    """(..., 6) -> (..., 4) (:func:`matrix_from_6d`)."""
    return quat_from_matrix(matrix_from_6d(d6))


def quat_slerp(a: np.ndarray, b: np.ndarray, t: np.ndarray | float) -> np.ndarray:
    """Spherical interpolation along the shorter arc; ``t`` broadcasts as (..., 1) or scalar."""
    t = np.asarray(t, dtype=float)
    if t.ndim:
        t = t[..., None]
    dot = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(dot < 0, -b, b)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin_theta = np.sin(theta)
    near = sin_theta < 1e-6
    wa = np.where(near, 1.0 - t, np.sin((1.0 - t) * theta) / np.where(near, 1.0, sin_theta))
    wb = np.where(near, t, np.sin(t * theta) / np.where(near, 1.0, sin_theta))
    return quat_normalize(wa * a + wb * b)


def quat_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Shortest-arc rotation taking direction u onto direction v. (..., 3) x (..., 3) -> (..., 4)."""
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    w = 1.0 + np.sum(u * v, axis=-1, keepdims=True)
    axis = np.cross(u, v)
    # opposite vectors: rotate by pi about any axis orthogonal to u
    ortho = np.cross(u, np.where(np.abs(u[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    axis = np.where(w < 1e-9, ortho, axis)
    return quat_normalize(np.concatenate([axis, np.where(w < 1e-9, 0.0, w)], axis=-1))


def quat_yaw(q: np.ndarray) -> np.ndarray:
    """Heading angle (radians, about +Y) of the rotated +Z axis. (..., 4) -> (...)."""
    forward = quat_rotate(q, np.broadcast_to([0.0, 0.0, 1.0], (*q.shape[:-1], 3)))
    return np.arctan2(forward[..., 0], forward[..., 2])


def quat_from_yaw(yaw: np.ndarray) -> np.ndarray:
    """Rotations about +Y by ``yaw`` radians. (...) -> (..., 4)."""
    yaw = np.asarray(yaw, dtype=float)
    return np.stack([np.zeros_like(yaw), np.sin(0.5 * yaw), np.zeros_like(yaw), np.cos(0.5 * yaw)], -1)
