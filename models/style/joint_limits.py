"""Human joint ranges and the soft limit that keeps the stylizer's poses inside them.

A style's gain and posture offset, extrapolated by a γ mix or doubled by the strength, can bend a joint past what a
body does (a head turned backwards, an elbow folded flat). The stylizer therefore passes its output through
:meth:`JointRanges.limit`: per styled joint, each rotation-vector component stays inside the range real people
reach, and so does the rotation angle |v|. The limit is soft: inside the range it is the identity (ordinary motion
leaves bit for bit as it came); beyond, the excess x is bent to :data:`MARGIN`·tanh(x / MARGIN), so a joint
approaches the range's edge plus the margin smoothly and never passes it. The range is widened to wherever the
stylizer's *input* already is: the limit never pulls the generator's own pose back, it only stops a style from
pushing a joint further out than the range or that pose.

The ranges are measured on real motion capture (``models/weights/stylizer/joint_ranges.json``; reproduce it with
``python -m gesturecast.tools.style.joint_ranges``): the Bandai dataset-1 takes (174 takes of 15 styles; bows,
dances, punches and runs besides gestures), per joint and axis the 0.1st and 99.9th percentiles of the rotation
vector's components and the 99.9th percentile of its angle (the rarest frames are left out: retargeting flips a few
near 180°). Bandai's skeleton has one chest joint, so the canonical UpperChest takes the Chest's range; the hands keep
only their angle (their axes differ between the generator's takes and Bandai's: ±π on each axis).
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from gesturecast.models.style.fitted_file import read_fitted, write_fitted
from gesturecast.models.style.params import STYLED_JOINTS

FORMAT = "gesturecast-joint-ranges-1"
MARGIN = np.radians(10.0)  # the most a joint may pass its range (or the input's pose), reached asymptotically
PERCENTILE = 0.1  # the share (%) of the takes' frames left out at each end of a range
DEFAULT_JOINT_RANGES = Path(str(resources.files("gesturecast.models"))) / "weights" / "stylizer" / "joint_ranges.json"


def soft_ceiling(x: np.ndarray, ceiling: np.ndarray) -> np.ndarray:
    """x where x ≤ ceiling, else ceiling + MARGIN·tanh((x − ceiling) / MARGIN): smooth (slope 1 at the ceiling),
    below ceiling + MARGIN."""
    excess = np.maximum(x - ceiling, 0.0)
    return np.where(x > ceiling, ceiling + MARGIN * np.tanh(excess / MARGIN), x)


@dataclass(frozen=True)
class JointRanges:
    """Per styled joint: ``low`` and ``high`` (S, 3) of each rotation-vector component, ``angle`` (S,) the largest
    rotation angle, radians."""

    low: np.ndarray
    high: np.ndarray
    angle: np.ndarray

    @staticmethod
    def measured(vectors: np.ndarray) -> JointRanges:
        """The ranges of real rotation vectors (T, S, 3) (module docstring)."""
        low = np.percentile(vectors, PERCENTILE, axis=0)  # (S, 3)
        high = np.percentile(vectors, 100.0 - PERCENTILE, axis=0)  # (S, 3)
        angle = np.percentile(np.linalg.norm(vectors, axis=-1), 100.0 - PERCENTILE, axis=0)  # (S,)
        return JointRanges(low, high, angle)

    def limit(self, styled: np.ndarray, given: np.ndarray) -> np.ndarray:
        """Styled rotation vectors (n, S, 3) kept softly within the ranges widened to the ``given`` input vectors
        (n, S, 3) they were made from (module docstring)."""
        high = np.maximum(self.high, given)  # (n, S, 3)
        low = np.minimum(self.low, given)  # (n, S, 3)
        boxed = -soft_ceiling(-soft_ceiling(styled, high), -low)  # (n, S, 3)
        angle = np.linalg.norm(boxed, axis=-1, keepdims=True)  # (n, S, 1)
        largest = np.maximum(self.angle[:, None], np.linalg.norm(given, axis=-1, keepdims=True))  # (n, S, 1)
        scale = np.where(angle > largest, soft_ceiling(angle, largest) / np.maximum(angle, 1e-12), 1.0)
        return boxed * scale

    def save(self, path: Path, meta: dict) -> None:
        write_fitted(path, {"format": FORMAT, "joints": list(STYLED_JOINTS), **meta,
                            "low": np.round(self.low, 4).tolist(), "high": np.round(self.high, 4).tolist(),
                            "angle": np.round(self.angle, 4).tolist()})

    @staticmethod
    def load(path: Path = DEFAULT_JOINT_RANGES) -> JointRanges:
        data = read_fitted(path, "joint-range file", FORMAT, "joints", STYLED_JOINTS)
        return JointRanges(*(np.asarray(data[key], dtype=np.float64) for key in ("low", "high", "angle")))
