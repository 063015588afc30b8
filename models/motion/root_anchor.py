"""Keeping the avatar where it stands: the root trajectory with a bounded distance and facing.

The generator's root channels are per-frame changes (planar velocity in the facing frame, yaw rate;
models/motion/motion_features.py). Integrated freely they drift: metres of travel and a turn to
profile over a minute of speech, which slides a VTuber's avatar out of the camera. This module
integrates the same channels with a leash, frame by frame (streaming and offline are the same code):

- ``free``: plain integration, the generated trajectory as the model made it;
- ``locked``: the hips stay at the anchor and face its direction (height and hip tilt still move);
- ``bounded`` (default): a leaky integrator whose state drifts back to the anchor with time constant
  ``recenter_s``, passed through a smooth saturation ``r → R·tanh(r / R)``. Small sways and weight
  shifts (|offset| ≪ R) pass almost unchanged; the distance never reaches R; the saturation is
  1-Lipschitz, so the output never moves faster than the leaky state (no pop at the bound). The
  facing yaw gets the same treatment with bound ``max_yaw_deg``.

Changing the mode re-anchors at the current pose, so a change never makes the avatar jump.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from gesturecast.controls import ROOT_MODES
from gesturecast.errors import UserError
from gesturecast.models.motion.motion_features import (
    ROOT_HEIGHT,
    ROOT_VELOCITY,
    ROOT_YAW_RATE,
    rotate_planar,
    wrap_angle,
)

RootMode = Enum("RootMode", {mode.upper(): mode for mode in ROOT_MODES}, type=str)  # BOUNDED, FREE, LOCKED


def parse_root_mode(text: str) -> RootMode:
    """A root mode from its name, or a one-line error listing the choices."""
    try:
        return RootMode(text)
    except ValueError:
        raise UserError(f"unknown root mode {text!r}: choose one of {', '.join(ROOT_MODES)}") from None


@dataclass(frozen=True)
class RootBounds:
    radius_m: float = 0.15  # the hips stay strictly within this distance of the anchor (ground plane)
    max_yaw_deg: float = 30.0  # and face within this angle of the anchor's direction
    recenter_s: float = 2.0  # time constant of the drift back to the anchor


def saturate(offset: np.ndarray, limit: float) -> np.ndarray:
    """Smooth radial saturation of a vector (..., n): length r → limit·tanh(r / limit), same direction."""
    length = np.linalg.norm(offset, axis=-1, keepdims=True)
    scale = np.where(length > 0.0, limit * np.tanh(length / limit) / np.maximum(length, 1e-300), 1.0)
    return offset * scale


class RootAnchor:
    """Streaming root integration (hips position (3,), facing yaw) under a :class:`RootMode`."""

    def __init__(self, mode: RootMode = RootMode.BOUNDED, bounds: RootBounds | None = None, fps: float = 30.0):
        self.bounds = bounds or RootBounds()
        self._leak = math.exp(-1.0 / (fps * self.bounds.recenter_s))  # per-frame decay of the offset state
        self.mode = mode
        self.reset()

    def reset(self) -> None:
        """Anchor at the origin facing +Z; the next frame is the stream's first."""
        self._anchor_xz = np.zeros(2)
        self._anchor_yaw = 0.0
        self._restart()

    def _restart(self) -> None:
        self._offset = np.zeros(2)  # leaky (bounded) or plain (free) planar offset from the anchor
        self._turn = 0.0  # the same for the facing yaw, radians
        self._started = False
        self.position_xz = self._anchor_xz.copy()
        self.yaw = self._anchor_yaw

    def set_mode(self, mode: RootMode) -> None:
        """Switch modes, re-anchored where the avatar stands now (no jump)."""
        if mode == self.mode:
            return
        self.mode = mode
        self._anchor_xz, self._anchor_yaw = self.position_xz.copy(), self.yaw
        started = self._started
        self._restart()
        self._started = started

    def step(self, frame_features: np.ndarray) -> tuple[np.ndarray, float]:
        """One frame's features (D,) → (hips position (3,), facing yaw in radians)."""
        frame_features = np.asarray(frame_features, dtype=np.float64)
        if self._started and self.mode != RootMode.LOCKED:
            self._integrate(frame_features)
        self._started = True
        return np.array([self.position_xz[0], frame_features[ROOT_HEIGHT][0], self.position_xz[1]]), self.yaw

    def _integrate(self, frame_features: np.ndarray) -> None:
        """Add one frame's planar velocity (moved along the current facing) and yaw rate to the state."""
        displacement = rotate_planar(frame_features[ROOT_VELOCITY], np.float64(self.yaw))  # (2,)
        yaw_rate = float(frame_features[ROOT_YAW_RATE][0])
        if self.mode == RootMode.FREE:
            self._offset = self._offset + displacement
            self._turn = float(wrap_angle(self._turn + yaw_rate))
            self.position_xz = self._anchor_xz + self._offset
            self.yaw = float(wrap_angle(self._anchor_yaw + self._turn))
            return
        self._offset = self._leak * self._offset + displacement
        self._turn = self._leak * self._turn + yaw_rate
        self.position_xz = self._anchor_xz + saturate(self._offset, self.bounds.radius_m)
        max_yaw = math.radians(self.bounds.max_yaw_deg)
        self.yaw = float(wrap_angle(self._anchor_yaw + max_yaw * math.tanh(self._turn / max_yaw)))


@dataclass
class RootTravel:
    """How far the hips went from where the stream started, frame by frame (constant memory): the largest
    ground-plane distance from the first frame, the net travel (first frame to the newest) and the largest
    facing angle away from the first frame's facing (wrapped to [0°, 180°])."""

    start_xz: np.ndarray | None = None
    start_yaw: float = 0.0
    max_distance_m: float = 0.0
    net_travel_m: float = 0.0
    max_facing_deg: float = 0.0

    def update(self, position: np.ndarray, yaw: float) -> None:
        """One frame's hips position (3,) and facing yaw (radians)."""
        planar = np.asarray(position, dtype=np.float64)[[0, 2]]  # (2,) ground plane
        if self.start_xz is None:
            self.start_xz, self.start_yaw = planar, float(yaw)
        self.net_travel_m = float(np.linalg.norm(planar - self.start_xz))
        self.max_distance_m = max(self.max_distance_m, self.net_travel_m)
        facing = abs(math.degrees(float(wrap_angle(np.float64(yaw - self.start_yaw)))))
        self.max_facing_deg = max(self.max_facing_deg, facing)

    def to_dict(self) -> dict:
        return {"max_distance_m": self.max_distance_m, "net_travel_m": self.net_travel_m,
                "max_facing_deg": self.max_facing_deg}
