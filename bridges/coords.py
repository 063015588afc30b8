"""Coordinate frames at the edges: internal → Unity, Unreal, right-handed Y-up.

Internal frame (docs/architecture.md, "Conventions"): right-handed, Y-up, the character faces +Z (its left is +X),
metres, quaternions XYZW. Each target frame is a fixed orthogonal basis change ``M`` (rows =
target axes written in internal coordinates) plus a length scale ``s``:

- position:  p' = s · M p
- rotation:  R' = M R Mᵀ. As a quaternion the vector part is an axial vector, so it picks up
  det(M) under a reflection: q' = (det(M) · M v, w). The angle is unchanged.

Unity (left-handed, Y-up, +Z forward, +X right, metres): the character's right is internal −X,
so M = diag(−1, 1, 1): p = (−x, y, z), q = (x, −y, −z, w)  (docs/architecture.md, "Conventions").

Unreal (left-handed, Z-up, +X forward, +Y right, centimetres): forward +X = internal +Z,
right +Y = internal −X, up +Z = internal +Y, so p = 100 · (z, −x, y) and, det(M) = −1,
q = (−qz, qx, −qy, w).

Right-handed Y-up (``internal``): identity.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gesturecast.errors import UserError

CENTIMETRES_PER_METRE = 100.0


@dataclass(frozen=True, eq=False)
class CoordinateFrame:
    """A target frame: ``basis`` (3, 3) rows = target axes in internal coordinates; ``scale`` per metre."""

    name: str
    basis: np.ndarray
    scale: float
    description: str

    @cached_property
    def handedness_sign(self) -> float:
        return float(np.sign(np.linalg.det(self.basis)))

    def position(self, p: np.ndarray) -> np.ndarray:
        """(..., 3) internal metres → (..., 3) target units."""
        return self.scale * np.asarray(p, dtype=np.float64) @ self.basis.T + 0.0  # + 0.0: no negative zeros

    def rotation(self, q: np.ndarray) -> np.ndarray:
        """(..., 4) internal XYZW → (..., 4) target XYZW (R' = M R Mᵀ)."""
        q = np.asarray(q, dtype=np.float64)
        out = np.empty_like(q)
        out[..., :3] = self.handedness_sign * q[..., :3] @ self.basis.T + 0.0
        out[..., 3] = q[..., 3]
        return out

    def to_internal_matrix(self) -> np.ndarray:
        """(3, 3) matrix taking target-frame positions back to internal metres (Mᵀ / s)."""
        return self.basis.T / self.scale


INTERNAL = CoordinateFrame("internal", np.eye(3), 1.0, "right-handed, Y-up, faces +Z, metres")
UNITY = CoordinateFrame("unity", np.diag([-1.0, 1.0, 1.0]), 1.0, "left-handed, Y-up, faces +Z, metres")
UNREAL = CoordinateFrame(
    "unreal",
    np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    CENTIMETRES_PER_METRE,
    "left-handed, Z-up, faces +X, centimetres",
)
FRAMES: dict[str, CoordinateFrame] = {f.name: f for f in (INTERNAL, UNITY, UNREAL)}


def coordinate_frame(name: str) -> CoordinateFrame:
    """Look a frame up by name (``internal``, ``unity``, ``unreal``); UserError if unknown."""
    try:
        return FRAMES[name]
    except KeyError:
        raise UserError(f"unknown coordinate frame {name!r}; choose one of {', '.join(FRAMES)}") from None
