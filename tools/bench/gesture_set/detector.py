"""The kinematic gesture detector of ``gesturecast bench gestures``, independent of the lexicon's stroke rules.

Joint positions are relative to the hips in the body's facing frame (x left, y up, z forward):

- a wave or a bye (a farewell waves) is a wrist above its shoulder for at least 0.25 s with a lateral swing (two or
  more turns of at least 2 cm);
- a one-handed raise is the named wrist 5 cm or more above its shoulder for 0.2 s; a cheer (raise-both) is both
  arms overhead: both wrists at least :data:`OVERHEAD_M` above the head joint for 0.2 s;
- a bow or a call (Bandai's call is a shout, leaning forward) is the head at least 12 cm further forward of the hips
  than the stream's median for 0.2 s;
- a guide is an arm held out in front and held there for 0.3 s: the wrist at least :data:`GUIDE_FORWARD` of the
  arm's length in front of its shoulder, the arm extended to :data:`GUIDE_EXTENSION` of its length or more, the
  wrist between :data:`GUIDE_HEIGHT` (fractions of the arm's length) of shoulder height, and moving (about the
  shoulder, averaged over :data:`STILL_FRAMES`) no faster than :data:`GUIDE_STILL` arm lengths a second. Calibrated
  on the fifteen recorded Bandai dataset-1 guide takes, each played at the amplitudes performances use (0.9, 1 and
  1.15): fourteen are found at every amplitude; the tired take, whose arm sweeps while out (0.6-0.8 arm lengths a
  second), is not. Of the recorded byes four of 30 (an arm held forward between waves), no bow and no call. The
  stillness is what tells a guide from the generator's own beats, which hold the wrists half an arm forward.

A detection's stroke is the first frame within 10 % of its signal's range below the peak (a guide's: of the wrist's
forward reach, from :data:`ARRIVAL_S` before the hold).
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.motion import MOTION_FPS

OVERHEAD_M = 0.15  # a cheer's wrists above the head joint (about the ears): arms up over the head
GUIDE_FORWARD = 0.55  # a guide's wrist in front of its shoulder, fraction of the arm's length
GUIDE_EXTENSION = 0.65  # shoulder-to-wrist distance, fraction of the arm's length
GUIDE_HEIGHT = (-0.6, 0.4)  # wrist height about the shoulder's, fractions of the arm's length
GUIDE_STILL = 0.3  # a held arm's wrist speed about its shoulder, arm lengths per second
STILL_FRAMES = 5  # the speed's moving average
ARRIVAL_S = 0.5  # a guide's stroke is looked for this long before its hold


def runs_of(mask: np.ndarray, min_frames: int) -> list[tuple[int, int]]:
    """[start, stop) of the runs of True at least ``min_frames`` long."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return [(a, b) for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a >= min_frames]


def swings(x: np.ndarray, min_swing: float = 0.02) -> int:
    """Turns of a lateral trace (m) whose swing between consecutive extremes is at least ``min_swing``."""
    turns, direction, extreme = 0, 0.0, float(x[0])
    for value in map(float, x[1:]):
        if direction == 0.0:
            if abs(value - extreme) >= min_swing:
                direction, extreme = float(np.sign(value - extreme)), value
        elif (value - extreme) * direction > 0:
            extreme = value
        elif abs(value - extreme) >= min_swing:
            turns, direction, extreme = turns + 1, -direction, value
    return turns


def arrival(signal: np.ndarray, start: int, stop: int, tolerance: float = 0.1) -> int:
    """The stroke of a detection: the first frame in [start, stop) within ``tolerance`` of the signal's range below
    its peak (a held pose counts from when it is reached)."""
    window = signal[start:stop]
    level = window.max() - tolerance * (window.max() - window.min())
    return start + int(np.flatnonzero(window >= level)[0])


class Detector:
    """The gesture detector over one stream's body-frame positions (T, J, 3) (rules: module docstring)."""

    def __init__(self, body: np.ndarray, names: tuple[str, ...]) -> None:
        self.body = body
        joint = names.index
        self.wrist = {side: body[:, joint(f"{side}Hand")] for side in ("Left", "Right")}  # (T, 3)
        self.shoulder = {side: body[:, joint(f"{side}UpperArm")] for side in ("Left", "Right")}
        self.arm_length = {side: float(np.median(np.linalg.norm(body[:, joint(f"{side}UpperArm")] - body[:, joint(
            f"{side}LowerArm")], axis=1) + np.linalg.norm(body[:, joint(f"{side}LowerArm")] - self.wrist[side],
            axis=1))) for side in ("Left", "Right")}
        self.head = body[:, joint("Head")]  # (T, 3)

    def height(self, side: str) -> np.ndarray:
        return self.wrist[side][:, 1] - self.shoulder[side][:, 1]

    def events(self, gesture: str) -> list[tuple[int, int, int]]:
        """(start, stop, stroke frame) of each detection of ``gesture``'s kind."""
        kind = gesture.split("-")[0]
        sides = {"left": ["Left"], "right": ["Right"]}.get(gesture.split("-")[-1], ["Left", "Right"])
        if kind in ("wave", "hand"):  # hand-up: Bandai's bye
            return [e for side in sides for e in self._waves(side)]
        if gesture == "raise-both":
            overhead = np.min([self.wrist[side][:, 1] - self.head[:, 1] for side in sides], axis=0)
            return self._peaks(overhead >= OVERHEAD_M, overhead, 6)
        if kind == "raise":
            heights = np.max([self.height(side) for side in sides], axis=0)
            return self._peaks(heights >= 0.05, heights, 6)
        if kind in ("bow", "call"):
            forward = self.head[:, 2] - np.median(self.head[:, 2])
            return self._peaks(forward >= 0.12, forward, 6)
        return self._guides(sides)

    def _guides(self, sides: list[str]) -> list[tuple[int, int, int]]:
        """An arm held out in front; the stroke is its arrival on the forward reach from :data:`ARRIVAL_S` before
        the hold (the hold starts once the arm has slowed down)."""
        held = np.max([self._reach(side) for side in sides], axis=0)  # (T,)
        forward = np.max([self.wrist[side][:, 2] - self.shoulder[side][:, 2] for side in sides], axis=0)  # (T,)
        back = int(ARRIVAL_S * MOTION_FPS)
        return [(a, b, arrival(forward, max(a - back, 0), b)) for a, b in runs_of(held >= GUIDE_FORWARD, 9)]

    def _reach(self, side: str) -> np.ndarray:
        """(T,) the wrist's distance in front of the shoulder (fraction of the arm's length) where the arm is
        extended and held still at a guide's height, else 0."""
        length = self.arm_length[side]
        offset = (self.wrist[side] - self.shoulder[side]) / length  # (T, 3) arm lengths
        speed = np.linalg.norm(np.diff(offset, axis=0, prepend=offset[:1]), axis=1) * MOTION_FPS  # (T,)
        speed = np.convolve(speed, np.ones(STILL_FRAMES) / STILL_FRAMES, mode="same")
        height = offset[:, 1]
        held_out = ((np.linalg.norm(offset, axis=1) >= GUIDE_EXTENSION) & (height >= GUIDE_HEIGHT[0])
                    & (height <= GUIDE_HEIGHT[1]) & (speed <= GUIDE_STILL))
        return np.where(held_out, offset[:, 2], 0.0)

    def _waves(self, side: str) -> list[tuple[int, int, int]]:
        height = self.height(side)
        found = []
        for start, stop in runs_of(height >= 0.0, int(0.25 * MOTION_FPS)):
            if swings(self.wrist[side][start:stop, 0]) >= 2:
                found.append((start, stop, arrival(height, start, stop)))
        return found

    @staticmethod
    def _peaks(mask: np.ndarray, signal: np.ndarray, min_frames: int) -> list[tuple[int, int, int]]:
        return [(a, b, arrival(signal, a, b)) for a, b in runs_of(mask, min_frames)]


def jerk(body: np.ndarray) -> np.ndarray:
    """(T-3,) mean joint jerk magnitude (m/s³) per frame of the body joints."""
    third = np.diff(body[:, :22], n=3, axis=0) * MOTION_FPS**3  # (T-3, 22, 3)
    return np.linalg.norm(third, axis=-1).mean(axis=1)
