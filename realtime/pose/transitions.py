"""Smooth changes while running: value ramps (style embedding, guidance scale, γ) and pose cross-fades.

Ramps are functions of an explicit time ``t`` in seconds. The session passes *stream time* (the capture
time of the frame being generated), so a live run and an offline run of the same file blend identically;
in live use stream time is read from the injected clock.

The easing is smoothstep s(u) = 3u² - 2u³: zero slope at both ends, so neither the start nor the end of a
change shows a velocity jump (GestureDiffuCLIP changes style sentence by sentence with smooth
transitions).
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.rotations import quat_slerp

DEFAULT_RAMP_S = 0.5


def smoothstep(u: np.ndarray | float) -> np.ndarray | float:
    """3u² - 2u³ on u clipped to [0, 1]."""
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


class Ramp:
    """Moves a value (scalar or vector) from its current value to a target over ``duration_s``.

    Retargeting mid-ramp starts from the value shown at that moment, so the output never jumps.
    """

    def __init__(self, initial: np.ndarray | float, duration_s: float = DEFAULT_RAMP_S, t: float = 0.0) -> None:
        if duration_s < 0:
            raise ValueError(f"ramp duration must be >= 0 s, got {duration_s}")
        self.duration_s = duration_s
        self._start_value = np.asarray(initial, dtype=np.float64)
        self._target = self._start_value
        self._start_time = t
        self._duration = 0.0

    @property
    def target(self) -> np.ndarray:
        return self._target

    def set_target(self, target: np.ndarray | float, t: float, duration_s: float | None = None) -> None:
        """Start moving toward ``target`` at time ``t`` (default duration: the ramp's own)."""
        target = np.asarray(target, dtype=np.float64)
        if target.shape != self._target.shape:
            raise ValueError(f"target shape {target.shape} differs from the ramp's {self._target.shape}")
        self._start_value = self.value(t)
        self._target = target
        self._start_time = t
        self._duration = self.duration_s if duration_s is None else duration_s

    def progress(self, t: float) -> float:
        """Eased progress in [0, 1] of the current change at time ``t``."""
        if self._duration <= 0.0:
            return 1.0
        return float(smoothstep((t - self._start_time) / self._duration))

    def value(self, t: float) -> np.ndarray:
        """The value at time ``t`` (the target once the ramp is over)."""
        w = self.progress(t)
        return self._start_value + w * (self._target - self._start_value)

    def done(self, t: float) -> bool:
        return self.progress(t) >= 1.0


def blend_poses(
    rotations_a: np.ndarray, root_a: np.ndarray, rotations_b: np.ndarray, root_b: np.ndarray, weight: float
) -> tuple[np.ndarray, np.ndarray]:
    """Pose a·(1-w) + b·w: per-joint slerp of (J, 4) XYZW rotations, linear (3,) root."""
    rotations = quat_slerp(rotations_a, rotations_b, weight)  # (J, 4)
    root = (1.0 - weight) * np.asarray(root_a) + weight * np.asarray(root_b)  # (3,)
    return rotations, root


class PoseCrossfade:
    """Cross-fades between two pose streams (A = idle, B = speech) with a smoothstep weight ramp.

    ``fade_to(1.0, t)`` goes into speech, ``fade_to(0.0, t)`` back to idle; ``mix`` blends one frame pair.
    """

    def __init__(self, duration_s: float = DEFAULT_RAMP_S, initial_weight_b: float = 0.0, t: float = 0.0) -> None:
        self._ramp = Ramp(initial_weight_b, duration_s, t)

    def fade_to(self, weight_b: float, t: float) -> None:
        """Start moving the weight of stream B toward ``weight_b`` (0..1) at time ``t`` (no-op if already)."""
        if not 0.0 <= weight_b <= 1.0:
            raise ValueError(f"cross-fade weight must be in [0, 1], got {weight_b}")
        if float(self._ramp.target) != weight_b:
            self._ramp.set_target(weight_b, t)

    def weight(self, t: float) -> float:
        return float(self._ramp.value(t))

    def mix(
        self, t: float, rotations_a: np.ndarray, root_a: np.ndarray, rotations_b: np.ndarray, root_b: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The blended pose at time ``t``: (rotations (J, 4), root (3,))."""
        return blend_poses(rotations_a, root_a, rotations_b, root_b, self.weight(t))
