"""Gesture size: the body's motion scaled around the idle, breathing pose (``intensity``, ``pause``).

Each joint's local rotation is slerped from the idle pose at the frame's time (breathing and sway,
:mod:`gesturecast.realtime.pose.idle`) toward the pose that reaches this stage (generated, cross-faded and stylized)
by the size s: s = 1 leaves the frames bit for bit, s = 0 gives the idle pose (the avatar stands, breathes and
blinks), s = 2 turns every joint twice as far from the idle pose. The hips' height follows the same scale; where the
avatar stands on the ground is the root mode's (``--root``). A pause is the size 0. A new size ramps in with the
smoothstep of the other live controls (:class:`~gesturecast.realtime.pose.transitions.Ramp`), from the first frame
built with it, so the same stream gives the same frames whether its poses are built one latent at a time or many.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.rotations import quat_slerp
from gesturecast.realtime.pose.idle import IdleMotion
from gesturecast.realtime.pose.transitions import DEFAULT_RAMP_S, Ramp

FULL_SIZE = 1.0  # the motion as it came


class GestureSize:
    """Scales (n, J, 4) body rotations and (n, 3) roots around ``idle`` by a size ramped over ``fade_s``."""

    def __init__(self, idle: IdleMotion, size: float = FULL_SIZE, fade_s: float = DEFAULT_RAMP_S) -> None:
        self.idle = idle
        self._ramp = Ramp(size, fade_s)

    def set_size(self, size: float, t: float) -> None:
        """Ramp toward ``size`` from stream time ``t`` (no-op when it is already the target)."""
        if float(self._ramp.target) != size:
            self._ramp.set_target(size, t)

    def apply(self, rotations: np.ndarray, roots: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The frames' rotations (n, J, 4) and roots (n, 3) at their stream times (n,) scaled by the size in effect;
        the same arrays while it is 1 throughout."""
        sizes = np.array([float(self._ramp.value(t)) for t in times])  # (n,)
        if np.all(sizes == FULL_SIZE):
            return rotations, roots
        scaled = quat_slerp(self.idle.rotations(times), rotations, sizes[:, None])  # (n, J, 4)
        base_height = self.idle.base_root[1]
        scaled_roots = roots.copy()  # (n, 3)
        scaled_roots[:, 1] = base_height + sizes * (roots[:, 1] - base_height)
        return scaled, scaled_roots
